!> Whether the step damps the velocity-law devices' bands (Newmark technique), or leaves
!> their forces alternating from step to step.
!>
!> A velocity-law device inside its band |s'| < eps is a dashpot c1 = P mu(eps) / eps between
!> its two masses (eq. 6): a first-order mode of rate c1 / m_r (m_r = m_i m_j / (m_i + m_j),
!> m_i for a device to the table), far faster than the structure when eps is small. Newmark's
!> rule gives it the amplification r = (1 - 2 (1 - gamma) x) / (1 + 2 gamma x) a step, with
!> x = c1 h / (2 m_r): for average acceleration (1 - x) / (1 + x), negative once x > 1. A
!> relative velocity that the band has not yet brought to its holding value (a device enters
!> the band near |s'| = eps with the force P mu, where holding the masses together takes far
!> less; a neighbour's transition changes that holding force) then alternates in sign from
!> step to step and decays like |r|^k, where the model's decays like exp(-2 x k). The band's
!> force c1 s' carries the alternation, +-A about its smooth course: the device's force
!> history, and the absolute accelerations of its masses (+-A / m), but not the displacements
!> (the trapezoid averages it out). Nothing else reports it while it costs no digits
!> (fd_result's 'digits lost' catches the extreme), and the static x > 1 cannot tell a run
!> that has it from one that does not (the paper's tests 1-3 have x = 1.3-1.9 and none).
!>
!> Measured on the force of each velocity-law device at its accepted steps inside the band
!> (alternation_step, called by the technique after each accepted step; no allocation in the
!> loop): the second difference D_k = F_k - 2 F_(k-1) + F_(k-2) over three steps in the band.
!> An alternation of amplitude A gives |D| ~ 4 A with the sign of D changing at every step; a
!> smooth force |D| ~ h^2 |F''|; a kink (the band's entry, a neighbour's transition) one large
!> D, not a run of them. An alternation is counted once D has changed sign alternation_run
!> times in a row, each |D| above 4 alternation_floor P mu: the largest |D| / 4 is the
!> device's band_alternation (N), the steps' time its band_alternation_time (s). A device with
!> a count is 'unresolved' (band_resolution); every run also reports the devices' x at dt1.
module fd_band_alternation
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, stat_no_memory
   use fd_model, only: model_type, moved_mass
   use fd_names, only: law_velocity
   use fd_device_state, only: device_state, phase_stick
   use fd_friction_velocity, only: sliding_mu
   use fd_result, only: result_type, resolution_none, resolution_resolved, resolution_unresolved
   implicit none
   private

   public :: alternation_type, band_watch, alternation_init, alternation_step, alternation_finish
   public :: alternation_floor, alternation_run

   !> Share of P mu below which an alternation is not counted.
   real(dp), parameter :: alternation_floor = 0.05_dp
   !> Sign changes of D in a row, each above the floor, before an alternation is counted:
   !> six forces in the band, which a kink cannot give.
   integer, parameter :: alternation_run = 3

   !> A device watched and what the step needs of its last forces.
   type :: band_watch
      integer :: dev = 0                      !! its number
      integer :: nin = 0                      !! of f1, f2, those in the band (0, 1 or 2)
      integer :: run = 0                      !! sign changes of D in a row above the floor
      real(dp) :: floor4 = 0.0_dp             !! 4 alternation_floor P mu: the |D| counted [N]
      real(dp) :: f1 = 0.0_dp, f2 = 0.0_dp    !! forces at the last two accepted steps [N]
      real(dp) :: d1 = 0.0_dp                 !! the last D [N]
   end type band_watch

   !> The velocity-law devices watched (one array of records: the step loads one descriptor).
   type :: alternation_type
      integer :: n = 0                        !! devices watched: velocity law, P mu > 0
      type(band_watch), allocatable :: w(:)   !! each of them
   end type alternation_type

contains

   !> The devices watched, every device's x at dt1 (res%band_x), and band_resolution
   !> 'resolved' when there is one ('not applicable' otherwise).
   subroutine alternation_init(model, dt1, al, res, error)
      type(model_type), intent(in) :: model         !! the model
      real(dp), intent(in) :: dt1                   !! main step [s]
      type(alternation_type), intent(out) :: al     !! the devices watched
      type(result_type), intent(inout) :: res       !! band_x and band_resolution set
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      integer :: d, q, stat
      real(dp) :: pmu

      res%band_resolution = resolution_none
      al%n = count(watched(model%dev(1:model%n_devices)%law, model%dev(1:model%n_devices)%p* &
                           model%dev(1:model%n_devices)%mu))
      allocate (al%w(al%n), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the bands of "//trim(fmt_int(al%n))// &
                          " velocity-law devices", stat_no_memory)
         return
      end if
      q = 0
      do d = 1, model%n_devices
         associate (dev => model%dev(d))
            if (.not. watched(dev%law, dev%p*dev%mu)) cycle
            q = q + 1
            pmu = dev%p*sliding_mu(dev, dev%eps)
            al%w(q) = band_watch(dev=d, floor4=4.0_dp*alternation_floor*pmu)
            res%band_x(d) = pmu/dev%eps*dt1/(2.0_dp*moved_mass(model, d))
         end associate
      end do
      if (al%n > 0) res%band_resolution = resolution_resolved
   end subroutine alternation_init

   !> A device the step may leave alternating: the velocity law with a band (P mu > 0).
   elemental logical function watched(law, pmu)
      integer, intent(in) :: law
      real(dp), intent(in) :: pmu

      watched = law == law_velocity .and. pmu > 0.0_dp
   end function watched

   !> An accepted step of length h: the watched devices' forces at its end (f, in the phases
   !> st of the next step) join their second differences; a counted alternation raises amp
   !> (res%band_alternation) and adds h to time (res%band_alternation_time).
   !> (Explicit-shape arrays: the call passes addresses only, no descriptors; it is made at
   !> every accepted step.)
   pure subroutine alternation_step(al, nd, h, st, f, amp, time)
      type(alternation_type), intent(inout) :: al   !! the devices watched, their last forces
      integer, intent(in) :: nd                     !! devices
      real(dp), intent(in) :: h                     !! the step's length [s]
      type(device_state), intent(in) :: st(nd)     !! every device's state at the step's end
      real(dp), intent(in) :: f(nd)                 !! every device's force at the step's end [N]
      real(dp), intent(inout) :: amp(nd)            !! per device: largest alternation counted [N]
      real(dp), intent(inout) :: time(nd)           !! per device: time of the counted steps [s]
      real(dp) :: dd
      integer :: q, d

      do q = 1, al%n
         associate (b => al%w(q))
            d = b%dev
            if (st(d)%phase /= phase_stick) then
               b%nin = 0
               b%run = 0
               cycle
            end if
            if (b%nin == 2) then
               dd = f(d) - 2.0_dp*b%f1 + b%f2
               if (abs(dd) > b%floor4 .and. dd*b%d1 < 0.0_dp) then
                  b%run = b%run + 1
                  if (b%run >= alternation_run) then
                     amp(d) = max(amp(d), 0.25_dp*abs(dd))
                     time(d) = time(d) + h
                  end if
               else
                  b%run = 0
               end if
               b%d1 = dd
            else
               b%nin = b%nin + 1
               b%d1 = 0.0_dp
            end if
            b%f2 = b%f1
            b%f1 = f(d)
         end associate
      end do
   end subroutine alternation_step

   !> band_resolution 'unresolved' when a device's alternation was counted.
   pure subroutine alternation_finish(res)
      type(result_type), intent(inout) :: res       !! band_resolution, from band_alternation

      if (res%band_resolution == resolution_resolved .and. any(res%band_alternation > 0.0_dp)) &
         res%band_resolution = resolution_unresolved
   end subroutine alternation_finish

end module fd_band_alternation
