!> The Moreau-Jean technique (`technique = 'moreau_jean'`): nonsmooth time stepping of
!>   M u'' + C u' + K u + sum_d b_d F_d = -M r x0''(t)
!> with unregularized Coulomb friction, at building scale.
!>
!> The theta-method on velocities, with the friction of the step as impulses: over a step h
!>   M (v1 - v) = h (f_theta - C v_theta - K u_theta) - B lambda,   u1 = u + h v_theta,
!>   v_theta = (1 - theta) v + theta v1,  u_theta = u + theta h v_theta,
!> i.e. (M + h theta C + h^2 theta^2 K) v1 = r - B lambda, where every device's impulse
!> lambda_d satisfies Coulomb's law at the end-of-step velocity (fd_impulse_solver): it
!> sticks (b_d'v1 = 0, |lambda_d| <= P mu h) or slides with lambda_d = P mu h sgn(b_d'v1).
!> The one-step problem is solved exactly by an active-set iteration on the structure's
!> reduced band system (O(n) per pattern for a shear building), with Lemke's method as
!> the fallback. No eps, no f; first order in time (docs/theory.md, section 12).
!>
!> Reported to the observer at the end of every step: u1, v1, the absolute acceleration
!> from equilibrium at t + h (Coulomb's law at the level of accelerations given v1) and the
!> device forces of that equilibrium (so that storey shears equal the inertia forces), the
!> devices' phases (sticking, sliding which way) and transitions. Energy: input and viscous
!> work and the friction work sum lambda_d Delta s_d / h over each step; the balance closes
!> to round-off for theta = 1/2 and leaves the method's numerical dissipation for theta > 1/2.
!>
!> A vertical component (&excitation3, planar bearings, the dense form): each bearing's normal
!> force N = N0 (1 + a_z / g) (fd_friction_planar, the one place that computes it) at the step's
!> theta point gives the step's disc h mu max(N, 0) and the pendulum's excess (N - N0) / R,
!> whose force at s of the step's start joins r (K keeps N0 / R: W is factored once); the end of
!> the step takes N there. N <= 0 (uplift): no friction, no restoring force; N's extremes and
!> the uplift are observed at the steps' ends, as Newmark does (docs/theory.md, 12.8).
!> The overturning (&bearings overturning = .true.) adds each bearing's dN (fd_overturning) from
!> the floors' accelerations of the accepted state (those of its end-of-step equilibrium, the
!> reported ones), held over the next step: explicit, one step behind, as Newmark takes it.
module fd_moreau_jean
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_real, fmt_int, allocation_error
   use fd_names, only: law_coulomb, law_name, excitation_types, technique_name, technique_moreau_jean, &
                       technique_newmark, damping_stiffness, damping_rayleigh, technique_integrates
   use fd_model, only: model_type, integration_type, device_type
   use fd_excitation, only: excitation_type, table_motion, table_acceleration, excitation_none, &
                            second_table_motion
   use fd_friction_planar, only: devices_at_normal_force, pendulum_excess, with_normal_force
   use fd_overturning, only: overturning_forces
   use fd_vertical_support, only: vertical_support, support_setup, support_advance, support_accept, support_forces, &
                                  support_energy
   use fd_kinematics, only: device_kinematics, device_nodes, devices_are_pairs, device_relative
   use fd_stiffness, only: influence_of
   use fd_matrices, only: structure_damping
   use fd_result, only: result_type
   use fd_observer, only: observer_type, observed_state, observer_init, sample_due, observe_peaks, observe_sample, &
                          observe_transitions, observe_start_energies, observe_end_energies, &
                         observe_poll, observe_stop_error, observe_work, observe_bearing_forces
   use fd_run_control, only: run_control
   use fd_stick_groups, only: groups_build, edge_relative
   use fd_group_system, only: gs_k_matvec, gs_k_absmatvec, gs_lowest_eigenvalue
   use fd_impulse_solver, only: impulse_solver, solver_setup, solve_impulses, predict_pattern, pattern_acceleration
   use fd_dense_impulse, only: dense_impulse, dense_setup, dense_factor, dense_solve, dense_acceleration, &
                               dense_k_times, impulse_banded, impulse_bandwidth
   implicit none
   private

   public :: run_moreau_jean, moreau_jean_check, stuck_period

   real(dp), parameter :: pi = acos(-1.0_dp)

   !> Everything the loop works on, allocated before it starts. The accepted state (n, nd, u, v,
   !> a, s, f, ag, ag2) is the observer's observed_state, which it extends.
   type, extends(observed_state) :: mj_work
      type(impulse_solver) :: p                           !! the one-step solver (devices between nodes)
      type(dense_impulse) :: di                           !! the dense one-step solver (any device, K_x)
      logical :: general = .false.                        !! the dense form is used
      integer :: linear_system = 0                        !! &integration's: dense form's storage
      real(dp), allocatable :: mr(:)                      !! (n) M r, r the table motion's direction
      ! a second horizontal component (dense form): its motion and M r2 (two = .false.: none)
      logical :: two = .false.
      type(excitation_type) :: exc2
      real(dp), allocatable :: mr2(:)
      ! a vertical component (dense form: the bearings' normal forces N = N0 (1 + a_z / g);
      ! three = .false.: constant): the devices at the N of the time normal_forces was last
      ! called for, each device's pendulum excess (N - N0) / R then, its force kp s, and each
      ! bearing's N at the accepted state
      logical :: three = .false.
      type(excitation_type) :: exc3
      ! the overturning (tilt): each bearing's dN from the floors' accelerations of the accepted
      ! state, held over the next step; N varies (varies) with a vertical component or it
      logical :: tilt = .false., varies = .false.
      real(dp), allocatable :: dn(:)                      !! (n_bearings) [N]
      ! the bearings on elastic vertical supports under a vertical component (elastic): their
      ! oscillators (fd_vertical_support), advanced over each step; normal_forces takes their N
      ! at the accepted state (mix = 0), the step's theta point (theta) or its end (1)
      logical :: elastic = .false.
      type(vertical_support) :: vs
      real(dp) :: mix = 0.0_dp
      type(device_type), allocatable :: dev(:)            !! (nd)
      real(dp), allocatable :: kp(:), fx(:)               !! (nd) [N/m], [N]
      real(dp), allocatable :: pn(:)                      !! (n_bearings) [N]
      real(dp), allocatable :: lam(:), wrel(:), fend(:)   !! (nd) dense form: impulses, b'v1, end forces
      integer, allocatable :: sig(:), sa(:)               !! (nd) dense form: statuses of a step, its end
      type(observer_type) :: obs                          !! peaks, history, energy balance
      integer :: ne = 0
      real(dp) :: a0 = 0.0_dp, a1 = 0.0_dp                !! C = a0 M + a1 K
      real(dp), allocatable :: u1(:), v1(:), r(:), du(:), kx(:), rabs(:)  !! (n)
      real(dp), allocatable :: sd(:)                      !! (nd)
      integer, allocatable :: phase0(:), phase1(:)        !! (nd) phases before and after a step
      integer, allocatable :: counted(:)                  !! (nd) phase last counted as a transition
      logical, allocatable :: pending(:)                  !! (nd) stopped from a slide at the last step
      integer, allocatable :: ta(:), tb(:)                !! (nd) transitions handed to the observer
      real(dp), allocatable :: g_step(:), g_force(:)      !! (ne) bounds: P mu h, P mu
      real(dp), allocatable :: f_edge(:)                  !! (ne) edge forces at the end of a step [N]
      real(dp), allocatable :: rel_edge(:)                !! (ne) edge relative displacement of a step [m]
      real(dp) :: w_fric = 0.0_dp                         !! friction work [J]
   end type mj_work

contains

   !> What the Moreau-Jean technique cannot integrate: a device whose law is not 'coulomb',
   !> a table motion it does not know, theta outside [1/2, 1]. Messages name the group, the
   !> variable, the value and what to set.
   subroutine moreau_jean_check(model, exc, opts, error)
      type(model_type), intent(in) :: model         !! the model
      type(excitation_type), intent(in) :: exc      !! the table motion
      type(integration_type), intent(in) :: opts    !! the settings (theta)
      type(error_type), allocatable, intent(out) :: error !! what cannot be integrated
      character(len=:), allocatable :: idx, tech
      integer :: d

      tech = "technique = '"//trim(technique_name(technique_moreau_jean))//"'"
      do d = 1, model%n_devices
         if (technique_integrates(technique_moreau_jean, model%dev(d)%law)) cycle
         idx = 'law('//trim(fmt_int(d))//')'
         if (model%dev(d)%partner > 0) then
            idx = 'law('//trim(fmt_int(model%dev(d)%source_index))//')'
            call fatal_error(error, "group &bearings: "//idx//" = '"//trim(law_name(model%dev(d)%law))// &
                             "' is invalid with "//tech//" of &integration: it integrates 'coulomb' bearings; "// &
                             "set "//idx//" = 'coulomb' or technique = 'newmark'")
            return
         end if
         call fatal_error(error, "group &friction: "//idx//" = '"//trim(law_name(model%dev(d)%law))// &
                          "' is invalid with "//tech//" of &integration: the Moreau-Jean technique "// &
                          "integrates unregularized Coulomb friction, 'coulomb' devices only; set "//idx// &
                          " = '"//trim(law_name(law_coulomb))//"', or technique = '"// &
                          trim(technique_name(technique_newmark))//"' with a regularized law for every device")
         return
      end do
      if (exc%kind < 1 .or. exc%kind > size(excitation_types)) then
         call fatal_error(error, "group &excitation: excitation_type (id "//trim(fmt_int(exc%kind))// &
                          ") is not a table motion the Moreau-Jean technique knows")
         return
      end if
      if (.not. (opts%theta >= 0.5_dp .and. opts%theta <= 1.0_dp)) then
         call fatal_error(error, "group &integration: theta = "//trim(fmt_real(opts%theta))// &
                          " is invalid with "//tech//": it must be between 0.5 and 1")
      end if
   end subroutine moreau_jean_check

   !> First period of the stuck system (every device with P mu > 0 a rigid link) from the
   !> lowest eigenvalue of its reduced band system. Errors as fd_matrices' stuck_first_mode.
   subroutine stuck_period(p, period, error)
      type(impulse_solver), intent(inout) :: p      !! the solver (its edges and springs)
      real(dp), intent(out) :: period               !! first period T [s]
      type(error_type), allocatable, intent(out) :: error !! no free DOF, rigid-body mode
      real(dp) :: lam, scale
      integer :: stat
      logical, allocatable :: all_stuck(:)

      period = 0.0_dp
      allocate (all_stuck(p%ne), stat=stat)
      call allocation_error(error, stat, "the stuck system's "//trim(fmt_int(p%ne))//" edges")
      if (allocated(error)) return
      all_stuck = .true.
      call groups_build(p%es, all_stuck, p%node_order)
      p%fvalid = .false.
      if (p%es%nr == 0) then
         call fatal_error(error, "the stuck system has no free DOF: every mass is locked to the table &
                          &by friction devices, so its first period is undefined (give period in &damping)")
         return
      end if
      call gs_lowest_eigenvalue(p%gs, p%es%grp, p%es%nr, lam, scale, error)
      if (allocated(error)) return
      if (lam <= 1.0e-12_dp*scale) then
         call fatal_error(error, "the stuck system has a rigid-body mode (first eigenvalue "// &
                          trim(fmt_real(lam))//"): add springs to the table or give period in &damping")
         return
      end if
      period = 2.0_dp*pi/sqrt(lam)
   end subroutine stuck_period

   !> Integrate a model whose devices all follow Coulomb's law by Moreau-Jean time stepping.
   subroutine run_moreau_jean(model, exc, opts, res, error, ctl, exc2, exc3)
      type(model_type), intent(in) :: model         !! validated model (all devices coulomb)
      type(excitation_type), intent(in) :: exc      !! table motion
      type(integration_type), intent(in) :: opts    !! n1, theta and output_every are used
      type(result_type), intent(out) :: res         !! histories and summary
      type(error_type), allocatable, intent(out) :: error !! singular system, LCP failure, stop
      type(run_control), intent(inout), target, optional :: ctl !! the run's control (fd_run_control)
      type(excitation_type), intent(in), optional :: exc2 !! a second horizontal component, along
                                                          !! the model's influence2 (kind none: none)
      type(excitation_type), intent(in), optional :: exc3 !! the vertical component: the bearings'
                                                          !! normal forces (kind none: none)
      type(mj_work) :: w
      real(dp) :: h, th, alpha, beta, cm, ck, t1, ag0, ag1, agt, xg, vg, e_kin, e_str, ein
      integer :: k, e, c0, c1, crate

      call system_clock(c0, crate)
      call moreau_jean_check(model, exc, opts, error)
      if (allocated(error)) return
      w%linear_system = opts%linear_system
      call setup(model, w, res, error)
      if (allocated(error)) return
      call second_table_motion(model, w%general, w%two, w%exc2, w%mr2, error, exc2)
      if (allocated(error)) return
      call observer_init(model, exc, opts, res%moreau_jean%setup%period_stuck, res, w%obs, error, ctl)
      if (allocated(error)) return
      ! a vertical component and the overturning act on planar bearings alone, which take the
      ! dense form
      if (w%general .and. res%n_bearings > 0) then
         if (present(exc3)) w%three = exc3%kind /= excitation_none
         if (w%three) w%exc3 = exc3
         w%tilt = model%overturning
         w%varies = w%three .or. w%tilt
         if (w%varies) call vertical_init(model, w, res%n_bearings, error)
         if (allocated(error)) return
      end if
      th = opts%theta
      h = exc%dt_record/opts%n1
      res%moreau_jean%ran = .true.
      res%moreau_jean%setup%dt1 = h
      res%moreau_jean%setup%damping_method = th > 0.5_dp   ! theta > 1/2 damps
      if (w%general) then
         call dense_run(model, exc, opts, w, res, error)
         if (allocated(error)) return
         call system_clock(c1)
         res%run_time = real(c1 - c0, dp)/real(max(crate, 1), dp)
         return
      end if
      ! W = M + h theta C + (h theta)^2 K = alpha M + beta K
      alpha = 1.0_dp + h*th*w%a0
      beta = h*th*w%a1 + (h*th)**2
      ! r = W v + h (f_theta - C v - K (u + theta h v)) = cm M v - K (ck v + h u) + h f_theta
      cm = 1.0_dp - h*(1.0_dp - th)*w%a0
      ck = h*(1.0_dp - th)*(w%a1 + h*th)
      w%g_step = h*w%p%es%pmu
      w%g_force = w%p%es%pmu

      ! initial state; devices moving at t = 0 slide that way, the others are decided by the
      ! acceleration problem (W = M, bounds P mu): its solution is the initial acceleration
      w%u = model%u0
      w%v = model%v0
      call table_motion(exc, 0.0_dp, xg, vg, ag0)
      do e = 1, w%ne
         w%p%sigma(e) = 0
         if (edge_relative(w%p%es, e, w%v) > 0.0_dp) w%p%sigma(e) = 1
         if (edge_relative(w%p%es, e, w%v) < 0.0_dp) w%p%sigma(e) = -1
      end do
      w%p%locked = w%p%sigma /= 0
      w%kx = w%a1*w%v + w%u
      call gs_k_matvec(w%p%gs, w%kx, w%r, -1.0_dp, 0.0_dp)
      w%r = w%r - model%mass*(ag0 + w%a0*w%v)
      w%rabs = model%mass*(abs(ag0) + w%a0*abs(w%v))
      call gs_k_absmatvec(w%p%gs, w%kx, w%rabs, 1.0_dp)
      call solve_impulses(w%p, w%r, w%rabs, 1.0_dp, 0.0_dp, w%g_force, w%a, error)
      if (allocated(error)) return
      w%p%locked = .false.
      call device_state(model, w, w%p%lam, w%phase0)
      call energies(w, e_kin, e_str)
      call start_observing(w, res, ag0, e_kin, e_str)

      do k = 1, w%obs%nsteps
         t1 = k*h
         call table_motion(exc, t1, xg, vg, ag1)
         agt = (1.0_dp - th)*ag0 + th*ag1
         w%kx = ck*w%v + h*w%u
         call gs_k_matvec(w%p%gs, w%kx, w%r, -1.0_dp, 0.0_dp)
         w%r = w%r + model%mass*(cm*w%v - h*agt)
         w%rabs = model%mass*(abs(cm*w%v) + h*abs(agt))
         call gs_k_absmatvec(w%p%gs, w%kx, w%rabs, 1.0_dp)
         if (k > 1) call predict_pattern(w%p, w%g_step)
         call solve_impulses(w%p, w%r, w%rabs, alpha, beta, w%g_step, w%v1, error)
         if (allocated(error)) return
         w%u1 = w%u + h*((1.0_dp - th)*w%v + th*w%v1)
         ! energy of the step: input, viscous and friction work over du = h v_theta
         w%du = w%u1 - w%u
         ein = agt*sum(model%mass*w%du)
         call gs_k_matvec(w%p%gs, w%du, w%kx, 1.0_dp, 0.0_dp)
         call observe_work(res, -ein, (w%a0*sum(model%mass*w%du**2) + w%a1*dot_product(w%du, w%kx))/h)
         do e = 1, w%ne
            w%rel_edge(e) = edge_relative(w%p%es, e, w%du)
            w%w_fric = w%w_fric + w%p%lam(e)*w%rel_edge(e)/h
         end do
         call device_work(w, h)
         ! acceleration at t1 from equilibrium with the end-of-step pattern held
         w%kx = w%a1*w%v1 + w%u1
         call gs_k_matvec(w%p%gs, w%kx, w%r, -1.0_dp, 0.0_dp)
         w%r = w%r - model%mass*(ag1 + w%a0*w%v1)
         call pattern_acceleration(w%p, w%r, w%g_force, w%a)
         ! the device forces of that equilibrium (not the step's mean lambda / h): the forces at
         ! t1 the storey shears and hysteresis loops are made of, in equilibrium with acc
         do e = 1, w%ne
            if (w%p%sa(e) == 0) then
               w%f_edge(e) = w%p%fa(e)
            else
               w%f_edge(e) = w%p%sa(e)*w%g_force(e)
            end if
         end do
         w%u = w%u1
         w%v = w%v1
         ag0 = ag1
         call device_state(model, w, w%f_edge, w%phase1)
         call end_step(w, res, k, t1, ag1, error)
         if (allocated(error)) return
      end do
      call count_transitions(w, res, .true.)
      call energies(w, e_kin, e_str)
      call observe_end_energies(w%obs, res, e_kin, e_str, 0.0_dp, w%w_fric)
      res%moreau_jean%factorizations = w%p%gs%factorizations
      res%moreau_jean%patterns = w%p%patterns
      res%moreau_jean%lcp_fallbacks = w%p%fallbacks
      call system_clock(c1)
      res%run_time = real(c1 - c0, dp)/real(max(crate, 1), dp)
   end subroutine run_moreau_jean

   !> Solver, damping coefficients, stuck period and work space.
   subroutine setup(model, w, res, error)
      type(model_type), intent(in) :: model
      type(mj_work), intent(inout) :: w
      type(result_type), intent(inout) :: res
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: eig_error
      real(dp) :: period, t_damp, om
      integer :: n, nd, stat, first
      integer, allocatable :: dev_i(:), dev_j(:)
      real(dp), allocatable :: pmu(:)

      n = model%n_dof
      nd = model%n_devices
      w%n = n
      w%nd = nd
      w%general = dense_form(model)
      if (w%general) then
         call dense_init(model, w, res, error)
         return
      end if
      ! the devices' nodes and forces as arrays of their own (a component of an array of
      ! derived type passed as an argument is copied to a temporary at the call)
      allocate (dev_i(nd), dev_j(nd), pmu(nd), stat=stat)
      call allocation_error(error, stat, trim(state_text(n)))
      if (allocated(error)) return
      call device_nodes(model, dev_i, dev_j, first)
      if (first /= 0) then
         call fatal_error(error, "the Moreau-Jean technique integrates devices between two nodes; device "// &
                          trim(fmt_int(first))//" is not")
         return
      end if
      pmu = model%dev%p*model%dev%mu
      call solver_setup(w%p, model%mass, model%spring_i, model%spring_j, model%spring_k, dev_i, dev_j, pmu, error)
      if (allocated(error)) return
      w%ne = w%p%ne
      ! C = a0 M + a1 K: the paper's psi K with the given or the stuck period, or Rayleigh
      call stuck_period(w%p, period, eig_error)
      t_damp = period
      w%a0 = 0.0_dp
      w%a1 = 0.0_dp
      select case (model%damping)
      case (damping_stiffness)
         if (model%period > 0.0_dp) then
            t_damp = model%period
         else if (allocated(eig_error)) then
            call move_alloc(eig_error, error)
            error%message = "&damping: damping_type = 'stiffness' needs the stuck first period, but "// &
                            error%message
            return
         end if
         w%a1 = t_damp*model%xi/pi
      case (damping_rayleigh)
         w%a0 = model%rayleigh_a0
         w%a1 = model%rayleigh_a1
      end select
      res%moreau_jean%setup%period_stuck = 0.0_dp
      res%moreau_jean%setup%xi_stuck = 0.0_dp
      if (.not. allocated(eig_error)) then
         res%moreau_jean%setup%period_stuck = period
         om = 2.0_dp*pi/period
         res%moreau_jean%setup%xi_stuck = (w%a0 + w%a1*om**2)/(2.0_dp*om)
      end if
      allocate (w%u(n), w%v(n), w%u1(n), w%v1(n), w%a(n), w%r(n), w%du(n), w%kx(n), w%rabs(n), &
                w%s(nd), w%sd(nd), w%f(nd), w%phase0(nd), w%phase1(nd), w%counted(nd), w%pending(nd), &
                w%ta(nd), w%tb(nd), w%g_step(w%ne), w%g_force(w%ne), w%f_edge(w%ne), &
                w%rel_edge(w%ne), stat=stat)
      call allocation_error(error, stat, trim(state_text(n)))
   end subroutine setup

   !> Whether the model takes the dense form of the one-step problem (fd_dense_impulse): a
   !> device not between two nodes, stiffness beyond springs (K_x), a table motion's
   !> direction over the DOFs or a planar bearing. Models of springs and node-pair devices
   !> keep the band form of their sticking groups.
   pure logical function dense_form(model) result(dense)
      type(model_type), intent(in) :: model         !! the model
      integer :: d

      dense = .not. devices_are_pairs(model) .or. model%n_kx > 0 .or. allocated(model%influence)
      ! planar bearings: their friction discs are solved in the dense form
      do d = 1, model%n_devices
         if (model%dev(d)%partner > 0) dense = .true.
      end do
   end function dense_form

   !> Setup of the dense form: its matrices, C = a0 M + a1 K (fd_matrices' structure_damping:
   !> the stuck system's first period on the null space of the devices' directions), work.
   subroutine dense_init(model, w, res, error)
      type(model_type), intent(in) :: model
      type(mj_work), intent(inout) :: w
      type(result_type), intent(inout) :: res
      type(error_type), allocatable, intent(out) :: error
      integer :: n, nd, i, stat

      n = w%n
      nd = w%nd
      call dense_setup(w%di, model, error, impulse_banded(n, w%linear_system))
      if (allocated(error)) return
      ! the summary's linear_system and half_bandwidth (impulse_bandwidth: -1 when dense)
      res%moreau_jean%storage = merge(2, 1, impulse_banded(n, w%linear_system))
      res%moreau_jean%bandwidth = merge(impulse_bandwidth(w%di), n - 1, res%moreau_jean%storage == 2)
      call structure_damping(model, w%a0, w%a1, res%moreau_jean%setup%period_stuck, &
                             res%moreau_jean%setup%xi_stuck, error)
      if (allocated(error)) return
      w%ne = nd
      allocate (w%u(n), w%v(n), w%u1(n), w%v1(n), w%a(n), w%r(n), w%du(n), w%kx(n), w%rabs(n), w%mr(n), &
                w%s(nd), w%sd(nd), w%f(nd), w%phase0(nd), w%phase1(nd), w%counted(nd), w%pending(nd), &
                w%ta(nd), w%tb(nd), w%g_step(nd), w%g_force(nd), w%f_edge(nd), w%rel_edge(nd), w%lam(nd), &
                w%wrel(nd), w%fend(nd), w%sig(nd), w%sa(nd), stat=stat)
      call allocation_error(error, stat, trim(state_text(n)))
      if (allocated(error)) return
      do i = 1, n
         w%mr(i) = model%mass(i)*influence_of(model, i)
      end do
      w%g_force = model%dev%p*model%dev%mu
   end subroutine dense_init

   !> The time-step loop of the dense form (run_moreau_jean's, with fd_dense_impulse's
   !> one-step problem: every device an edge of its own, r the table motion's direction).
   subroutine dense_run(model, exc, opts, w, res, error)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      type(integration_type), intent(in) :: opts
      type(mj_work), intent(inout) :: w
      type(result_type), intent(inout) :: res
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: h, th, cm, ck, t1, ag0, ag1, agt, xg, vg, e_kin, e_str, ein, b0, b1, bt, az0, az1
      integer :: k, d

      az0 = 0.0_dp
      az1 = 0.0_dp
      b0 = 0.0_dp
      b1 = 0.0_dp
      bt = 0.0_dp
      th = opts%theta
      h = exc%dt_record/opts%n1
      cm = 1.0_dp - h*(1.0_dp - th)*w%a0
      ck = h*(1.0_dp - th)*(w%a1 + h*th)
      call dense_factor(w%di, 1.0_dp + h*th*w%a0, h*th*w%a1 + (h*th)**2, error)
      if (allocated(error)) return
      w%g_step = h*w%g_force
      w%u = model%u0
      w%v = model%v0
      call table_motion(exc, 0.0_dp, xg, vg, ag0)
      if (w%two) call table_motion(w%exc2, 0.0_dp, xg, vg, b0)
      if (w%three) az0 = table_acceleration(w%exc3, 0.0_dp)
      if (w%tilt) then
         ! the overturning at the start: the floors at the table's acceleration (the structure at
         ! rest relative to it: its acceleration is not known before the friction, which takes N)
         w%a = 0.0_dp
         call overturning_forces(model, w%a, ag0, b0, w%dn)
      end if
      if (w%varies) call normal_forces(model, az0, 1.0_dp, w, w%g_force)
      ! devices moving at t = 0 slide that way, the others by the acceleration problem
      do d = 1, w%nd
         w%wrel(d) = device_relative(model, d, w%v)
         w%sig(d) = int(sign(1.0_dp, w%wrel(d)))
         if (w%wrel(d) == 0.0_dp .or. w%g_force(d) <= 0.0_dp) w%sig(d) = 0
      end do
      call dense_end_state(model, w, ag0, b0, az0, w%u, w%v, error)
      if (allocated(error)) return
      call dense_device_state(model, w, w%phase0)
      call dense_energies(w, e_kin, e_str)
      ! the normal forces before the first row, which holds them
      if (w%varies) call observe_bearing_forces(res, model, 0.0_dp, 0.0_dp, az0, w%tilt, w%vs, w%pn, w%dn)
      call start_observing(w, res, ag0, e_kin, e_str, b0)
      do k = 1, w%obs%nsteps
         t1 = k*h
         call table_motion(exc, t1, xg, vg, ag1)
         agt = (1.0_dp - th)*ag0 + th*ag1
         ! r = cm M v - K (ck v + h u) - h M r_table agt
         w%kx = ck*w%v + h*w%u
         call dense_k_times(w%di, w%kx, w%r, -1.0_dp, 0.0_dp)
         w%r = w%r + model%mass*cm*w%v - h*agt*w%mr
         if (w%two) then
            call table_motion(w%exc2, t1, xg, vg, b1)
            bt = (1.0_dp - th)*b0 + th*b1
            w%r = w%r - h*bt*w%mr2
         end if
         if (w%three) az1 = table_acceleration(w%exc3, t1)
         if (w%elastic) then
            ! the vertical supports over the step (a_z linear in it); N at its theta point
            call support_advance(w%vs, 1, t1, az0, az1)
            w%mix = th
         end if
         if (w%varies) then
            ! the step's friction bounds h N mu and pendulum excess at its theta point (as its
            ! load f_theta; the overturning's dN of the step's start), the excess's force kp s
            ! with s of its start (w%s: a force, as Newmark's)
            call normal_forces(model, (1.0_dp - th)*az0 + th*az1, h, w, w%g_step)
            call excess_forces(model, w, w%u, -h, w%r)
         end if
         call dense_solve(w%di, w%r, w%g_step, w%v1, w%lam, w%wrel, w%sig, error)
         if (allocated(error)) return
         w%u1 = w%u + h*((1.0_dp - th)*w%v + th*w%v1)
         w%du = w%u1 - w%u
         ein = agt*sum(w%mr*w%du)
         if (w%two) ein = ein + bt*sum(w%mr2*w%du)
         call dense_k_times(w%di, w%du, w%kx, 1.0_dp, 0.0_dp)
         call observe_work(res, -ein, (w%a0*sum(model%mass*w%du**2) + w%a1*dot_product(w%du, w%kx))/h)
         do d = 1, w%nd
            w%rel_edge(d) = device_relative(model, d, w%du)
            w%w_fric = w%w_fric + w%lam(d)*w%rel_edge(d)/h
            w%obs%device_work(d) = w%obs%device_work(d) + w%lam(d)*w%rel_edge(d)/h
            w%obs%slip_travel(d) = w%obs%slip_travel(d) + abs(w%rel_edge(d))
         end do
         ! the pendulum excess's work over the step, with the devices' (as Newmark's)
         if (w%varies) call excess_work(w)
         w%mix = 1.0_dp
         call dense_end_state(model, w, ag1, b1, az1, w%u1, w%v1, error)
         if (allocated(error)) return
         if (w%elastic) then
            ! the vertical supports move on: the ground's work on them and their dashpots'
            call support_accept(w%vs)
            call observe_work(res, w%vs%w_in1, w%vs%w_damp1)
            w%mix = 0.0_dp
         end if
         w%u = w%u1
         w%v = w%v1
         ag0 = ag1
         b0 = b1
         az0 = az1
         call dense_device_state(model, w, w%phase1)
         ! the overturning's dN of the accepted state, from its end-of-step accelerations (the
         ! next step's, one step behind)
         if (w%tilt) call overturning_forces(model, w%a, ag1, b1, w%dn)
         if (w%varies) call observe_bearing_forces(res, model, t1, h, az1, w%tilt, w%vs, w%pn, w%dn)
         call end_step(w, res, k, t1, ag1, error, b1)
         if (allocated(error)) return
      end do
      call count_transitions(w, res, .true.)
      call dense_energies(w, e_kin, e_str)
      call observe_end_energies(w%obs, res, e_kin, e_str, 0.0_dp, w%w_fric)
      res%moreau_jean%factorizations = w%di%factorizations
      res%moreau_jean%patterns = w%di%lcp_solves
      res%moreau_jean%lcp_fallbacks = 0
   end subroutine dense_run

   !> The acceleration (relative to the table) and the device forces at an instant from
   !> equilibrium, the step's statuses w%sig held (fd_dense_impulse's dense_acceleration).
   subroutine dense_end_state(model, w, ag, ag2, az, u, v, error)
      type(model_type), intent(in) :: model
      type(mj_work), intent(inout) :: w
      real(dp), intent(in) :: ag, ag2, az, u(:), v(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: d

      w%kx = w%a1*v + u
      call dense_k_times(w%di, w%kx, w%r, -1.0_dp, 0.0_dp)
      w%r = w%r - w%mr*ag - w%a0*w%di%mass*v
      if (w%two) w%r = w%r - w%mr2*ag2
      ! a varying N: the bounds N mu and the pendulum excess's force at the instant (the
      ! overturning's dN that of the last accepted state)
      if (w%varies) then
         call normal_forces(model, az, 1.0_dp, w, w%g_force)
         call excess_forces(model, w, u, -1.0_dp, w%r)
      end if
      call dense_acceleration(w%di, w%r, w%g_force, w%sig, w%a, w%fend, w%sa, error, w%wrel)
      if (allocated(error) .or. .not. w%varies) return
      ! the devices' forces: the friction's and the excess's (both act along b)
      do d = 1, w%nd
         w%fend(d) = w%fend(d) + w%fx(d)
      end do
   end subroutine dense_end_state

   !> A varying normal force (a vertical component, the overturning): the devices' copies and
   !> work arrays (set up once: the loop allocates nothing).
   subroutine vertical_init(model, w, nb, error)
      type(model_type), intent(in) :: model
      type(mj_work), intent(inout) :: w
      integer, intent(in) :: nb                       !! bearings
      type(error_type), allocatable, intent(out) :: error
      integer :: stat

      allocate (w%dev(w%nd), w%kp(w%nd), w%fx(w%nd), w%pn(nb), w%dn(nb), stat=stat)
      if (stat == 0 .and. w%three) call support_setup(w%nd, model%dev, 1, w%vs, stat)
      call allocation_error(error, stat, trim(state_text(w%n)))
      if (allocated(error)) return
      w%elastic = w%vs%nb > 0
      w%dn = 0.0_dp
      w%dev = model%dev(1:w%nd)
      w%kp = 0.0_dp
      w%fx = 0.0_dp
   end subroutine vertical_init

   !> The devices at the vertical acceleration az (fd_friction_planar's devices_at_normal_force:
   !> a bearing's p = max(N, 0), N = N0 (1 + az / g), plus w%dn with the overturning), their
   !> bounds scale P mu into g (h: the impulses' h P mu; 1: the forces' P mu) and their pendulum
   !> excesses (N - N0) / R into w%kp (0 for every device but a curved bearing's components).
   pure subroutine normal_forces(model, az, scale, w, g)
      type(model_type), intent(in) :: model
      real(dp), intent(in) :: az, scale
      type(mj_work), intent(inout) :: w
      real(dp), intent(out) :: g(:)
      integer :: d, b

      if (w%tilt) then
         do b = 1, size(model%ot_dev)
            d = model%ot_dev(b)
            call with_normal_force(model%dev(d), az, w%dev(d), w%dn(b))
            call with_normal_force(model%dev(d + 1), az, w%dev(d + 1), w%dn(b))
         end do
      else
         call devices_at_normal_force(w%nd, model%dev, az, w%dev)
      end if
      if (w%elastic) then
         if (w%tilt) then
            call support_forces(w%vs, w%mix, w%nd, w%dev, w%dn)
         else
            call support_forces(w%vs, w%mix, w%nd, w%dev)
         end if
      end if
      do d = 1, w%nd
         g(d) = scale*(w%dev(d)%p*w%dev(d)%mu)
         w%kp(d) = 0.0_dp
         if (w%dev(d)%partner > 0) w%kp(d) = pendulum_excess(w%dev(d))
      end do
   end subroutine normal_forces

   !> The pendulum excesses' forces kp s at the displacements u into w%fx, added times c to r
   !> along each device's b (the K of the structure holds N0 / R; the rest is a force).
   subroutine excess_forces(model, w, u, c, r)
      type(model_type), intent(in) :: model
      type(mj_work), intent(inout) :: w
      real(dp), intent(in) :: u(:)
      real(dp), intent(in) :: c
      real(dp), intent(inout) :: r(:)
      integer :: d

      do d = 1, w%nd
         w%fx(d) = 0.0_dp
         if (w%kp(d) == 0.0_dp) cycle
         w%fx(d) = w%kp(d)*device_relative(model, d, u)
         r = r + (c*w%fx(d))*w%di%b(:, d)
      end do
   end subroutine excess_forces

   !> The work of the pendulum excesses' forces over the step's relative displacements
   !> (w%rel_edge), with the friction's: the devices' work and the balance's friction term.
   pure subroutine excess_work(w)
      type(mj_work), intent(inout) :: w
      integer :: d

      do d = 1, w%nd
         if (w%fx(d) == 0.0_dp) cycle
         w%w_fric = w%w_fric + w%fx(d)*w%rel_edge(d)
         w%obs%device_work(d) = w%obs%device_work(d) + w%fx(d)*w%rel_edge(d)
      end do
   end subroutine excess_work

   !> Device kinematics, forces and phases of the dense form (statuses of the step).
   pure subroutine dense_device_state(model, w, phase)
      type(model_type), intent(in) :: model
      type(mj_work), intent(inout) :: w
      integer, intent(out) :: phase(:)

      call device_kinematics(model, w%u, w%v, w%s, w%sd)
      w%f = w%fend
      phase = w%sig
   end subroutine dense_device_state

   !> Kinetic and strain energy of the current state (dense form).
   subroutine dense_energies(w, e_kin, e_str)
      type(mj_work), intent(inout) :: w
      real(dp), intent(out) :: e_kin, e_str
      real(dp) :: ek_v, ep_v

      e_kin = 0.5_dp*sum(w%di%mass*w%v**2)
      call dense_k_times(w%di, w%u, w%kx, 1.0_dp, 0.0_dp)
      e_str = 0.5_dp*dot_product(w%u, w%kx)
      ! the vertical supports' beside the structure's
      call support_energy(w%vs, ek_v, ep_v)
      e_kin = e_kin + ek_v
      e_str = e_str + ep_v
   end subroutine dense_energies

   !> The observation of the state at t = 0 and its phases (phase0), common to both forms:
   !> the transitions counted from them, its energies, its sample and its peaks.
   subroutine start_observing(w, res, ag0, e_kin, e_str, ag2)
      type(mj_work), intent(inout) :: w
      type(result_type), intent(inout) :: res
      real(dp), intent(in) :: ag0            !! table acceleration at t = 0 [m/s2]
      real(dp), intent(in) :: e_kin, e_str   !! kinetic and strain energy at t = 0 [J]
      real(dp), intent(in), optional :: ag2  !! the second component's at t = 0 [m/s2]

      w%counted = w%phase0
      w%pending = .false.
      call observe_start_energies(w%obs, e_kin, e_str, 0.0_dp)
      w%ag = ag0
      w%ag2 = 0.0_dp
      if (w%two .and. present(ag2)) then
         w%ag2 = ag2
         call observe_sample(w%obs, res, 0.0_dp, ag0, w%u, w%v, w%a, w%s, w%sd, w%f, w%phase0, ag2=ag2)
      else
         call observe_sample(w%obs, res, 0.0_dp, ag0, w%u, w%v, w%a, w%s, w%sd, w%f, w%phase0)
      end if
      call observe_peaks(res, 0.0_dp, w%observed_state)
   end subroutine start_observing

   !> The end of step k, common to both forms, once the state at t1 and its device phases
   !> (phase1) are known: transitions counted, peaks, a sample when due (an error if the
   !> solution is not finite), the stop request polled (a requested stop is an error).
   subroutine end_step(w, res, k, t1, ag1, error, ag2)
      type(mj_work), intent(inout) :: w
      type(result_type), intent(inout) :: res
      integer, intent(in) :: k               !! the step
      real(dp), intent(in) :: t1             !! its end [s]
      real(dp), intent(in) :: ag1            !! table acceleration at t1 [m/s2]
      type(error_type), allocatable, intent(out) :: error !! not finite, or a requested stop
      real(dp), intent(in), optional :: ag2  !! the second component's at t1 [m/s2]
      logical :: stopped, two

      two = w%two .and. present(ag2)
      call count_transitions(w, res, .false.)
      w%phase0 = w%phase1
      w%ag = ag1
      w%ag2 = 0.0_dp
      if (two) w%ag2 = ag2
      call observe_peaks(res, t1, w%observed_state)
      res%moreau_jean%steps = res%moreau_jean%steps + 1
      if (sample_due(w%obs, k)) then
         if (.not. all(ieee_is_finite(w%u)) .or. .not. all(ieee_is_finite(w%a))) then
            call fatal_error(error, "moreau_jean: the solution is not finite at t = "//trim(fmt_real(t1))//" s")
            return
         end if
         if (two) then
            call observe_sample(w%obs, res, t1, ag1, w%u, w%v, w%a, w%s, w%sd, w%f, w%phase1, ag2=ag2)
         else
            call observe_sample(w%obs, res, t1, ag1, w%u, w%v, w%a, w%s, w%sd, w%f, w%phase1)
         end if
      end if
      call observe_poll(w%obs, t1, stopped)
      if (stopped) call observe_stop_error(w%obs, error)
   end subroutine end_step

   !> What the state's memory is for, in a message: "the state of n_dof = n DOFs".
   pure function state_text(n) result(text)
      integer, intent(in) :: n                      !! the deck's n_dof
      character(len=48) :: text
      text = "the state of n_dof = "//trim(fmt_int(n))//" DOFs"
   end function state_text

   !> Device kinematics, forces (shared out of the edge forces f_edge) and phases (the
   !> statuses of the step's one-step problem) from the solver's edges.
   pure subroutine device_state(model, w, f_edge, phase)
      type(model_type), intent(in) :: model
      type(mj_work), intent(inout) :: w
      real(dp), intent(in) :: f_edge(:)
      integer, intent(out) :: phase(:)
      integer :: d, e

      call device_kinematics(model, w%u, w%v, w%s, w%sd)
      do d = 1, w%nd
         e = w%p%es%dev_edge(d)
         if (e == 0) then
            w%f(d) = 0.0_dp
            phase(d) = 0
         else
            w%f(d) = w%p%es%dev_sign(d)*w%p%es%dev_share(d)*f_edge(e)
            phase(d) = w%p%es%dev_sign(d)*w%p%sigma(e)
         end if
      end do
   end subroutine device_state

   !> Each device's share of its edge's friction work over the step (its P mu over the
   !> edge's: the share of the edge's force it carries) and its slip travel |ds|, added to
   !> the observer's totals here (a call a device and step would cost 4 % of a building's
   !> step, callgrind). A device without an edge (P mu = 0) carries no force and never slides.
   pure subroutine device_work(w, h)
      type(mj_work), intent(inout) :: w
      real(dp), intent(in) :: h
      integer :: d, e

      do d = 1, w%nd
         e = w%p%es%dev_edge(d)
         if (e == 0) cycle
         w%obs%device_work(d) = w%obs%device_work(d) + w%p%es%dev_share(d)*(w%p%lam(e)*w%rel_edge(e)/h)
         w%obs%slip_travel(d) = w%obs%slip_travel(d) + abs(w%rel_edge(e))
      end do
   end subroutine device_work

   !> Count the phase transitions of the step (phase0 -> phase1) with the observer. A device
   !> that stops from a slide is counted one step later: if it then slides the other way, it
   !> passed through zero velocity within the step (the one-step problem lands on w = 0 for a
   !> fraction 2 P mu / (|D| + P mu) of such reversals, D the driving force, whatever h) and
   !> the pair counts as one slip reversal, as the exact technique counts it; otherwise as
   !> slip-to-stick (and stick-to-slip). At the end of the run (`last`) a pending stop counts.
   subroutine count_transitions(w, res, last)
      type(mj_work), intent(inout) :: w
      type(result_type), intent(inout) :: res
      logical, intent(in) :: last
      integer :: d, p, c

      do d = 1, w%nd
         p = w%phase1(d)
         c = w%counted(d)
         w%ta(d) = c          ! after the first transition of the step
         w%tb(d) = c          ! after the second (a stop and a start in one count)
         if (w%pending(d)) then
            w%pending(d) = .false.
            if (last .or. p == 0) then
               w%ta(d) = 0
               w%tb(d) = 0
            else if (p == -c) then
               w%ta(d) = p
               w%tb(d) = p
            else
               w%ta(d) = 0
               w%tb(d) = p
            end if
         else if (p /= c .and. .not. last) then
            if (c /= 0 .and. p == 0) then
               w%pending(d) = .true.
            else
               w%ta(d) = p
               w%tb(d) = p
            end if
         end if
      end do
      call observe_transitions(res, w%counted, w%ta)
      call observe_transitions(res, w%ta, w%tb)
      w%counted = w%tb
   end subroutine count_transitions

   !> Kinetic and strain energy of the current state.
   subroutine energies(w, e_kin, e_str)
      type(mj_work), intent(inout) :: w
      real(dp), intent(out) :: e_kin, e_str

      e_kin = 0.5_dp*sum(w%p%gs%mass*w%v**2)
      call gs_k_matvec(w%p%gs, w%u, w%kx, 1.0_dp, 0.0_dp)
      e_str = 0.5_dp*dot_product(w%u, w%kx)
   end subroutine energies

end module fd_moreau_jean
