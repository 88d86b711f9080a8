!> The structural model: lumped masses with one horizontal DOF each (displacements relative
!> to the moving table, node 0), linear springs, viscous damping and friction devices,
!> and the settings of the time integration and of the output. The ids and names of laws,
!> damping types and techniques, and every default, come from fd_names (re-exported here).
module fd_model
   use fd_kinds, only: dp
   use fd_names, only: damping_none, damping_stiffness, damping_rayleigh, damping_modal, &
                       law_velocity, law_hysteretic, law_coulomb, law_name, &
                       technique_newmark, technique_event_driven, technique_moreau_jean, technique_name, &
                       default_eps, default_eps1, default_f, default_xi, default_period, &
                       default_rayleigh_a0, default_rayleigh_a1, default_technique, default_beta, &
                       default_gamma, default_n1, default_n2, default_n, default_check_correctness, &
                       default_dt_min, default_output_every, default_write_history, default_theta, &
                       default_linear_system, default_refinement, &
                       mu_constant, mu_exponential, mu_table, label_len, max_mu_points, &
                       system_stuck, system_free, default_mu_law, default_mode_system, default_n_modes
   implicit none
   private

   public :: model_type, device_type, integration_type, output_type
   public :: damping_none, damping_stiffness, damping_rayleigh, damping_modal
   public :: law_velocity, law_hysteretic, law_coulomb, law_name
   public :: technique_newmark, technique_event_driven, technique_moreau_jean, technique_name
   public :: mu_constant, mu_exponential, mu_table, label_len, max_mu_points
   public :: system_stuck, system_free
   public :: source_friction, source_brace, source_isolator, source_floor_brace, source_bearing
   public :: sliding_mu, device_parameter

   ! where a device (or spring) of the model comes from in the deck
   integer, parameter :: source_friction = 0  !! &friction (or &springs)
   integer, parameter :: source_brace = 1     !! &braces (a friction damper in series with a brace)
   integer, parameter :: source_isolator = 2  !! &isolators (a sliding isolator)
   integer, parameter :: source_floor_brace = 3 !! &floor_braces (a brace at a plan position of rigid floors)
   integer, parameter :: source_bearing = 4   !! &bearings (a component of a planar bearing)

   !> One friction device. Its geometry is its direction b over the DOFs, kept in the model
   !> (dev_ptr, dev_dof, dev_coef) and reached only through fd_kinematics: its relative
   !> displacement is s = b' u and its force F enters the equations of motion as b F (eq. 5).
   !> A device between two nodes has b = e_i - e_j (e_i on the table), made from node_i
   !> and node_j by fd_kinematics' set_pair_directions.
   type :: device_type
      integer :: node_i = 0        !! first node (1..n_dof) of a device between two nodes
      integer :: node_j = 0        !! second node (0..n_dof, 0 = table)
      integer :: law = law_velocity !! friction law id
      real(dp) :: p = 0.0_dp       !! normal force P [N]
      real(dp) :: mu = 0.0_dp      !! friction coefficient [-]
      real(dp) :: eps = default_eps   !! velocity law band eps [m/s], eqs. 6-7
      real(dp) :: eps1 = default_eps1 !! hysteretic end of sliding eps1 [m/s], eq. 2
      real(dp) :: f = default_f       !! hysteretic sticking displacement f [m], eq. 3
      ! mu as a function of the sliding velocity (velocity law); mu is mu_max for 'exponential'
      ! and the table's value at its last point for 'table'
      integer :: mu_law = default_mu_law   !! mu_constant, mu_exponential or mu_table
      real(dp) :: mu_min = 0.0_dp          !! exponential: mu at zero velocity [-]
      real(dp) :: mu_rate = 0.0_dp         !! exponential: rate [s/m]
      integer :: n_mu_points = 0           !! table: points used
      real(dp) :: mu_v(max_mu_points) = 0.0_dp   !! table: sliding velocities, increasing [m/s]
      real(dp) :: mu_at(max_mu_points) = 0.0_dp  !! table: mu at each velocity [-]
      character(len=label_len) :: label = ''     !! name in outputs ('damper 2')
      integer :: source = source_friction  !! the deck group it comes from
      integer :: source_index = 0          !! its index in that group
      ! a planar bearing (&bearings) is two devices, its components along x and y, each with
      ! its own direction b; each names the other (0: an ordinary one-dimensional device)
      integer :: partner = 0               !! the bearing's other component (0: none)
      integer :: component = 0             !! 1: the bearing's x component, 2: its y component
      ! a bearing whose normal force varies (a vertical component): p is its current value,
      ! p_static the one whose pendulum stiffness p_static / radius K holds
      real(dp) :: radius = 0.0_dp          !! a bearing's pendulum radius R [m] (0: flat)
      real(dp) :: p_static = 0.0_dp        !! a bearing's normal force in K's pendulum stiffness [N]
      ! a bearing's vertical support (fd_vertical_support): its share p_static / g of the mass
      ! on a spring kv with a dashpot of ratio zeta_v; kv = 0: rigid
      real(dp) :: kv = 0.0_dp              !! vertical stiffness [N/m] (0: rigid support)
      real(dp) :: zeta_v = 0.0_dp          !! vertical damping, ratio of critical [-]
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
      real(dp) :: xi = default_xi             !! damping ratio of the stuck first mode [-]
      real(dp) :: period = default_period     !! stuck first period T [s]; 0 = computed
      real(dp) :: rayleigh_a0 = default_rayleigh_a0 !! Rayleigh mass factor [1/s]
      real(dp) :: rayleigh_a1 = default_rayleigh_a1 !! Rayleigh stiffness factor [s]
      integer :: n_devices = 0                !! number of friction devices
      type(device_type), allocatable :: dev(:) !! the friction devices
      ! the devices' directions b_d, compressed by device: b_d has the coefficient dev_coef(k)
      ! at DOF dev_dof(k) for k = dev_ptr(d) .. dev_ptr(d + 1) - 1 (fd_kinematics reads them)
      integer, allocatable :: dev_ptr(:)      !! start of each device's terms (n_devices + 1)
      integer, allocatable :: dev_dof(:)      !! DOF of each term (1..n_dof)
      real(dp), allocatable :: dev_coef(:)    !! coefficient of each term [-]
      ! when every device joins two nodes, those nodes (node_i, node_j; 0 = the table) by
      ! device: the time-step loops' fast path (fd_kinematics); not allocated otherwise
      integer, allocatable :: dev_nodes(:, :) !! (2, n_devices)
      ! the stiffness that is no spring between two nodes (rigid floors' frames): K_x,
      ! symmetric, by its entries on and above the diagonal (fd_stiffness reads them)
      integer :: n_kx = 0                     !! entries of K_x
      integer, allocatable :: kx_i(:)         !! row of each entry (1..n_dof)
      integer, allocatable :: kx_j(:)         !! column (kx_i <= kx_j)
      real(dp), allocatable :: kx_v(:)        !! value [N/m, N, or N m]
      ! the table motion's direction over the DOFs, r: the load is -M r a_g (not allocated:
      ! r = 1, every DOF a translation along the table's motion)
      real(dp), allocatable :: influence(:)   !! (n_dof) [-]
      real(dp), allocatable :: influence2(:)  !! (n_dof) r2 of the second component, if any [-]
      ! a building of rigid floors (fd_floors): floor f has the DOFs 3f - 2 (ux), 3f - 1 (uy)
      ! and 3f (rz) at its centre of mass
      integer :: n_floors = 0                 !! floors (0: a model of masses, &model)
      real(dp), allocatable :: floor_x(:)     !! centre of mass of each floor in plan, x [m]
      real(dp), allocatable :: floor_y(:)     !! and y [m]
      real(dp), allocatable :: floor_height(:) !! height of the storey below each floor [m]; 0 = not given
      real(dp), allocatable :: floor_inertia(:) !! rotational inertia of each floor [kg m2]
      real(dp), allocatable :: floor_lx(:)    !! plan dimension along x of each floor [m]; 0 = not given
      real(dp), allocatable :: floor_ly(:)    !! and along y [m] (a rectangle about the centre of mass)
      logical :: p_delta = .false.            !! the gravity loads' geometric stiffness is in K_x
      ! the overturning of rigid floors on planar bearings (&bearings overturning = .true.;
      ! fd_overturning): bearing b, whose x component is device ot_dev(b), on storey ot_storey(b),
      ! takes dN_b = -ot_arm(:, b) . O, O the moments of the inertia forces of the floors it carries
      logical :: overturning = .false.        !! the bearings' normal forces take the overturning
      integer, allocatable :: ot_dev(:)       !! (n_bearings) each bearing's x component
      integer, allocatable :: ot_storey(:)    !! (n_bearings) its storey
      real(dp), allocatable :: ot_arm(:, :)   !! (2, n_bearings) S^-1 (x_b - x_c, y_b - y_c) [1/m]
      ! the forces of a storey that are no springs or devices between its two nodes (the
      ! frames and braces of rigid floors): its shear adds sum coef (u + a1 v)(dof) over the
      ! entries (xs_*) of the storey, and sum coef F(dev) over the entries (xd_*)
      integer, allocatable :: xs_storey(:)    !! storey of each stiffness entry
      integer, allocatable :: xs_dof(:)       !! its DOF
      real(dp), allocatable :: xs_coef(:)     !! its coefficient [N/m, or N]
      integer, allocatable :: xd_storey(:)    !! storey of each device entry
      integer, allocatable :: xd_dev(:)       !! its device
      real(dp), allocatable :: xd_coef(:)     !! its coefficient [-]
      ! 'rayleigh' damping given as xi at two natural modes (resolved into a0, a1 when read)
      integer :: mode_i = 0                   !! first mode (0: a0, a1 given)
      integer :: mode_j = 0                   !! second mode
      integer :: mode_system = default_mode_system !! modes of the stuck or the free system
      ! 'modal' damping: C = U diag(modal_d) U', U = M Phi over the kept modes of the stuck
      ! system (fd_modal_damping, when the deck is read); no n x n matrix
      real(dp), allocatable :: modal_xi(:)    !! the ratios given: one for every kept mode, or one each [-]
      integer :: modal_modes = 0              !! modes kept (0 = the default)
      real(dp), allocatable :: modal_u(:, :)  !! (n_dof, kept) M phi_k [kg]
      real(dp), allocatable :: modal_d(:)     !! (kept) 2 xi_k w_k / (phi_k' M phi_k) [1/(kg s)]
      ! names and storeys, for the engineering outputs
      character(len=label_len), allocatable :: dof_label(:)    !! name of each DOF ('floor 3')
      integer :: n_storeys = 0                !! storeys (drift, shear) named by the deck
      integer, allocatable :: storey_i(:)     !! upper node of each storey (1..n_dof)
      integer, allocatable :: storey_j(:)     !! lower node (0..n_dof, 0 = table)
      real(dp), allocatable :: storey_height(:) !! height [m]; 0 = not given
      character(len=label_len), allocatable :: storey_label(:) !! name of each storey
      integer, allocatable :: spring_source(:) !! the deck group of each spring (source_*)
      ! what produced the model (echoed in the summary; the record's hash is in record_info)
      character(len=64) :: deck_sha256 = ''   !! SHA-256 of the deck
   end type model_type

   !> Settings of the time integration: the technique, Newmark and the step control.
   type :: integration_type
      integer :: technique = default_technique  !! technique id (fd_names)
      real(dp) :: beta = default_beta           !! Newmark beta
      real(dp) :: gamma = default_gamma         !! Newmark gamma
      integer :: n1 = default_n1                !! dt1 = dt_record / n1
      integer :: n2 = default_n2                !! dt2 = dt1 / n2 on a phase change
      real(dp) :: n_corr = default_n            !! n of the correctness condition, eqs. 9 and 12
      logical :: check = default_check_correctness !! check the correctness condition
      real(dp) :: dt_min = default_dt_min       !! floor of the step halving [s]; 0 = dt2 / 2**10
      real(dp) :: theta = default_theta         !! theta of the Moreau-Jean technique, 0.5..1
      integer :: output_every = default_output_every !! output every k dt1 steps; 0 = at the record step (n1)
      integer :: linear_system = default_linear_system !! storage of the effective stiffness (fd_names)
      integer :: refinement = default_refinement !! how a dt1 step is refined (fd_names)
      integer :: n_modes = default_n_modes      !! natural modes reported per system (&output)
   end type integration_type

   !> Where and what to write.
   type :: output_type
      character(len=:), allocatable :: dir   !! output directory (created if missing)
      character(len=:), allocatable :: name  !! base name of the files
      logical :: history = default_write_history !! write the time-history CSV
      integer, allocatable :: history_dofs(:)    !! DOFs in the history (not allocated: all)
      integer, allocatable :: history_devices(:) !! devices in the history (not allocated: all)
   end type output_type

contains

   !> Friction coefficient at the sliding speed |v|: mu itself (constant), the exponential
   !> mu_max - (mu_max - mu_min) exp(-rate |v|) with mu_max = mu, or linear between the table's
   !> points (constant before the first and after the last).
   elemental real(dp) function sliding_mu(dev, v) result(mu)
      type(device_type), intent(in) :: dev   !! device parameters
      real(dp), intent(in) :: v              !! sliding velocity (its magnitude is used) [m/s]
      real(dp) :: speed, w
      integer :: k, n

      speed = abs(v)
      select case (dev%mu_law)
      case (mu_exponential)
         mu = dev%mu - (dev%mu - dev%mu_min)*exp(-dev%mu_rate*speed)
      case (mu_table)
         n = dev%n_mu_points
         if (speed <= dev%mu_v(1)) then
            mu = dev%mu_at(1)
         else if (speed >= dev%mu_v(n)) then
            mu = dev%mu_at(n)
         else
            do k = 2, n
               if (speed <= dev%mu_v(k)) exit
            end do
            w = (speed - dev%mu_v(k - 1))/(dev%mu_v(k) - dev%mu_v(k - 1))
            mu = dev%mu_at(k - 1) + w*(dev%mu_at(k) - dev%mu_at(k - 1))
         end if
      case default
         mu = dev%mu
      end select
   end function sliding_mu

   !> The value of a device's real &friction variable by its name ('p', 'mu', 'eps', 'eps1',
   !> 'f'); 0 for a blank or another name (a friction law names its band and its sticking
   !> coupling by the variable that sets them, fd_friction).
   elemental real(dp) function device_parameter(dev, name) result(value)
      type(device_type), intent(in) :: dev        !! the device
      character(len=*), intent(in) :: name        !! the variable, lower case

      select case (name)
      case ('p')
         value = dev%p
      case ('mu')
         value = dev%mu
      case ('eps')
         value = dev%eps
      case ('eps1')
         value = dev%eps1
      case ('f')
         value = dev%f
      case default
         value = 0.0_dp
      end select
   end function device_parameter

end module fd_model
