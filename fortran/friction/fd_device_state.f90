!> State of one friction device during a run. Every friction law writes its force in the
!> current phase as F = ks*s + cs*sdot + f0 (s, sdot: relative displacement and velocity),
!> so that the time-step loop sees a device as a stiffness ks and a damping cs (both
!> entering the effective stiffness along the device's direction) and a load f0.
module fd_device_state
   use fd_kinds, only: dp
   implicit none
   private

   public :: device_state, phase_stick, phase_slip_pos, phase_slip_neg, device_force
   public :: law_traits_type, stuck_none, stuck_rigid, stuck_spring, stuck_dashpot

   integer, parameter :: phase_stick = 0     !! sticking (adherence)
   integer, parameter :: phase_slip_pos = 1  !! sliding with positive relative velocity
   integer, parameter :: phase_slip_neg = -1 !! sliding with negative relative velocity

   ! how a sticking device joins the stuck system (a law's traits)
   integer, parameter :: stuck_none = 0      !! not at all (a law without a case)
   integer, parameter :: stuck_rigid = 1     !! a rigid link (exact Coulomb)
   integer, parameter :: stuck_spring = 2    !! a spring, its sticking stiffness (hysteretic)
   integer, parameter :: stuck_dashpot = 3   !! a dashpot, its band's coupling (velocity)

   !> What a friction law says of itself, whatever its device's parameters: each law module
   !> answers one (`<law>_traits`), fd_friction's law_traits gives a law's.
   type :: law_traits_type
      integer :: stuck = stuck_none                !! how it joins the stuck system (stuck_*)
      character(len=4) :: band_name = ''           !! the &friction variable of its band ('' none)
      character(len=4) :: coupling_name = ''       !! the variable that sets its sticking coupling
      logical :: checks_correctness = .false.      !! Newmark checks its correctness condition
      logical :: checks_stick_ringing = .false.    !! its sticking spring may ring (fd_stick_ringing)
      logical :: checks_band_alternation = .false. !! its band may alternate (fd_band_alternation)
      logical :: stores_energy = .false.           !! it stores elastic energy (friction_energy)
      logical :: mu_of_speed = .false.             !! mu may depend on the sliding speed (mu_law)
   end type law_traits_type

   !> Phase and force coefficients of one device.
   type :: device_state
      integer :: phase = phase_stick   !! stick, slip + or slip -
      real(dp) :: centre = 0.0_dp      !! hysteretic law: s at which the elastic force is zero [m]
      logical :: armed = .false.       !! hysteretic law: |sdot| has reached eps1 in this slip
      real(dp) :: dir = 0.0_dp         !! a planar bearing's component: its component of the
                                       !! unit sliding direction while it slides (fd_friction_planar)
      real(dp) :: ks = 0.0_dp          !! stiffness in this phase [N/m]
      real(dp) :: cs = 0.0_dp          !! damping in this phase [N s/m]
      real(dp) :: f0 = 0.0_dp          !! constant force in this phase [N]
   end type device_state

contains

   !> Friction force of a device in its current phase [N].
   elemental function device_force(st, s, sdot) result(force)
      type(device_state), intent(in) :: st !! device state
      real(dp), intent(in) :: s            !! relative displacement [m]
      real(dp), intent(in) :: sdot         !! relative velocity [m/s]
      real(dp) :: force                    !! F = ks s + cs sdot + f0

      force = st%ks*s + st%cs*sdot + st%f0
   end function device_force

end module fd_device_state
