!> The structural model: lumped masses with one horizontal DOF each (displacements relative
!> to the moving table, node 0), linear springs, viscous damping and friction devices,
!> and the settings of the time integration.
module fd_model
   use fd_kinds, only: dp
   implicit none
   private

   public :: model_type, device_type, integration_type
   public :: damping_none, damping_stiffness, damping_rayleigh
   public :: law_velocity, law_hysteretic, law_coulomb, law_name

   integer, parameter :: damping_none = 0      !! no viscous damping
   integer, parameter :: damping_stiffness = 1 !! C = psi K, psi = T xi / pi (the paper)
   integer, parameter :: damping_rayleigh = 2  !! C = a0 M + a1 K

   integer, parameter :: law_velocity = 1   !! velocity model, eqs. 6-11
   integer, parameter :: law_hysteretic = 2 !! hysteretic model, eqs. 2-5
   integer, parameter :: law_coulomb = 3    !! exact event-driven Coulomb friction

   !> One friction device between node_i and node_j (node 0 = the table).
   !> Its relative displacement is s = u(node_i) - u(node_j); its force F acts
   !> as +F on node_i's equation of motion and -F on node_j's (eq. 5).
   type :: device_type
      integer :: node_i = 0        !! first node (1..n_dof)
      integer :: node_j = 0        !! second node (0..n_dof, 0 = table)
      integer :: law = law_velocity !! friction law id
      real(dp) :: p = 0.0_dp       !! normal force P [N]
      real(dp) :: mu = 0.0_dp      !! friction coefficient [-]
      real(dp) :: eps = 1.0e-3_dp  !! velocity law band eps [m/s], eqs. 6-7
      real(dp) :: eps1 = 1.0e-3_dp !! hysteretic end of sliding eps1 [m/s], eq. 2
      real(dp) :: f = 1.0e-5_dp    !! hysteretic sticking displacement f [m], eq. 3
   end type device_type

   !> The whole structural model.
   type :: model_type
      integer :: n_dof = 0                    !! number of degrees of freedom
      real(dp), allocatable :: mass(:)        !! lumped masses [kg]
      real(dp), allocatable :: u0(:)          !! initial relative displacements [m]
      real(dp), allocatable :: v0(:)          !! initial relative velocities [m/s]
      integer :: n_springs = 0                !! number of linear springs
      integer, allocatable :: spring_i(:)     !! first node of each spring (1..n_dof)
      integer, allocatable :: spring_j(:)     !! second node of each spring (0..n_dof)
      real(dp), allocatable :: spring_k(:)    !! spring stiffness [N/m]
      integer :: damping = damping_none       !! damping model id
      real(dp) :: xi = 0.0_dp                 !! damping ratio of the stuck first mode [-]
      real(dp) :: period = 0.0_dp             !! stuck first period T [s]; 0 = computed
      real(dp) :: rayleigh_a0 = 0.0_dp        !! Rayleigh mass factor [1/s]
      real(dp) :: rayleigh_a1 = 0.0_dp        !! Rayleigh stiffness factor [s]
      integer :: n_devices = 0                !! number of friction devices
      type(device_type), allocatable :: dev(:) !! the friction devices
   end type model_type

   !> Settings of the Newmark integration and of the step control.
   type :: integration_type
      real(dp) :: beta = 0.25_dp     !! Newmark beta
      real(dp) :: gamma = 0.5_dp     !! Newmark gamma
      integer :: n1 = 20             !! dt1 = dt_record / n1
      integer :: n2 = 50             !! dt2 = dt1 / n2 on a phase change
      real(dp) :: n_corr = 10.0_dp   !! n of the correctness condition, eqs. 9 and 12
      logical :: check = .true.      !! check the correctness condition
      real(dp) :: dt_min = 0.0_dp    !! floor of the step halving [s]; 0 = dt2 / 2**10
      integer :: output_every = 0    !! output every k dt1 steps; 0 = at the record step (n1)
   end type integration_type

contains

   !> Name of a friction law, as written in decks.
   pure function law_name(law) result(name)
      integer, intent(in) :: law              !! law id
      character(len=16) :: name               !! its name, left-adjusted
      select case (law)
      case (law_velocity)
         name = 'velocity'
      case (law_hysteretic)
         name = 'hysteretic'
      case (law_coulomb)
         name = 'coulomb'
      case default
         name = 'unknown'
      end select
   end function law_name

end module fd_model
