!> The time-step loop: Newmark integration (average acceleration by default) of
!>   M u'' + C u' + K u + sum_d b_d F_d = -M r x0''(t)
!> with the paper's two step sizes: dt1 = dt_record / n1, and a step in which any friction
!> device changes phase is redone from its start with n2 steps dt2 = dt1 / n2. A step that
!> violates the correctness condition (eqs. 9, 12) is redone with dt2 and then by halving
!> down to dt_min; a violation left at the floor is counted and reported, never hidden.
!> With `refinement = 'nested'` the redone dt1 step is split by the prime factors of n2,
!> smallest first (n2 = 50: dt1/2, dt1/10, dt2), and only a piece whose own trial step has a
!> phase change or a violation is split further: transitions are still taken in steps of
!> dt2, the stretches of the dt1 step without one in the largest piece that has none.
!> With `refinement = 'implicit'` (not the paper's) such a step is instead taken again in the
!> phases it ends in (settle_phases: the return mapping of a Newton-Raphson code), and refined
!> only when they do not settle.
!>
!> In each phase a device is linear, F = ks s + cs s' + f0, so a step solves one linear
!> system with the effective stiffness K^ = K + (gamma/(beta h)) C + M/(beta h^2) +
!> sum_d kd_d b_d b_d', kd_d = ks + (gamma/(beta h)) cs. K^ is held by the structure-aware
!> kernel fd_banded (dense for a few DOFs, else banded in a reverse Cuthill-McKee ordering;
!> memory linear in the number of DOFs): one system per step size (dt1, dt2, dt2/2, ...,
!> dt_min), all copies of one set-up system, each factored the first time its step size is
!> used. When the pattern of sticking devices has changed since a system was last used, its
!> factor is updated (rank-one updates and downdates, or a refactorization from the first
!> changed column when that is cheaper: spd_update_devices), never refactored from scratch.
!> Where the band after ordering is wide, K^ is instead fd_sparse's (CHOLMOD's factor, phase
!> changes by the Woodbury identity on it: linear_system = 'sparse', or chosen by 'auto' when a
!> step costs less so, choose_sparse).
!> K and C (C = a0 M + a1 K, the damping of fd_matrices' structure_damping) are never formed
!> densely; nothing in this module holds an n x n array, and nothing allocates once the loop
!> has started.
module fd_newmark
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_real, fmt_int, stat_no_memory
   use fd_names, only: technique_integrates, law_name, law_choices, excitation_types, technique_name, technique_newmark, &
                       technique_event_driven, technique_moreau_jean, linear_system_auto, linear_system_dense, &
                       linear_system_banded, linear_system_sparse, refinement_nested, refinement_implicit
   use fd_model, only: model_type, integration_type, device_type
   use fd_names, only: excitation_none
   use fd_excitation, only: excitation_type, table_motion, table_acceleration, grid_motion, grid_init, &
                            grid_acceleration, second_table_motion
   use fd_matrices, only: structure_damping
   use fd_woodbury, only: woodbury_type, woodbury_setup, woodbury_factor, woodbury_correct, lowrank_matvec, &
                          lowrank_form
   use fd_kinematics, only: device_kinematics, add_device, relative_motion, device_forces, device_nodes
   use fd_stiffness, only: stiffness_form, general_form, influence_of
   use fd_banded, only: spd_system, spd_setup, spd_factor, spd_update_devices, spd_solve, spd_k_matvec, &
                        spd_c_matvec, spd_kc_matvec, spd_auto, spd_dense, spd_banded, spd_is_dense, spd_bandwidth, &
                        spd_copy, spd_dense_max_n
   use fd_sparse, only: sparse_system, sparse_available, sparse_setup, sparse_factor, sparse_update_devices, &
                        sparse_solve, sparse_k_matvec, sparse_c_matvec, sparse_kc_matvec, sparse_free, sparse_band, &
                        sparse_factor_entries, sparse_nonzeros
   use fd_device_state, only: device_state, device_force, phase_stick
   use fd_friction_planar, only: pendulum_excess, with_normal_force, devices_at_normal_force, &
                                 normal_force_range
   use fd_overturning, only: overturning_forces
   use fd_vertical_support, only: vertical_support, support_setup, support_advance, support_accept, support_forces, &
                                  support_energy
   use fd_friction, only: friction_init, friction_step, friction_settle, follows_velocity, friction_follow, &
                          friction_energy, friction_capacity
   use fd_result, only: result_type
   use fd_run_control, only: run_control
   use fd_observer, only: observer_type, observed_state, observer_init, sample_due, observe_start_energies, observe_peaks, &
                          observe_sample, observe_transitions, observe_violations, observe_end_energies, &
                          observe_poll, observe_stop_error, observe_work, observe_bearing_forces
   use fd_step_limits, only: halving_levels, unresolved_band, max_nested, nested_splits, max_settle, max_follow, &
                             follow_tol
   use fd_stick_ringing, only: ringing_type, ringing_init, ringing_changed, ringing_finish, stat_time, stat_sd2, &
                               stat_fmax, stat_damping, ringing_normal_force
   use fd_band_alternation, only: alternation_type, alternation_init, alternation_step, alternation_normal_force, &
                                  alternation_finish
   implicit none
   private

   public :: run_newmark, newmark_check

   !> linear_system = 'sparse' (fd_sparse), beside fd_banded's spd_auto, spd_dense, spd_banded
   integer, parameter :: path_sparse = -1
   !> 'auto' asks CHOLMOD's analysis only above this half-bandwidth: a band this narrow is
   !> the factor's own fill (a chain, a plane frame), and the reference decks keep their path
   integer, parameter :: auto_band = 32
   !> Cost of an entry of the sparse factor or K^ in a step, in entries of the band (CHOLMOD's
   !> simplicial solve and the compressed-column products against LAPACK's band routines,
   !> measured on bench/matrix_scale.py's towers and plans, where they cost about the same
   !> per step at 6 n (kb + 1) = 3 to 4 (2 nnz(L) + 4 nnz(K^)))
   real(dp), parameter :: sparse_weight = 4.0_dp
   !> The path of each &integration linear_system, indexed by its id (fd_names: auto, dense,
   !> banded, sparse in that order)
   integer, parameter :: solver_path(linear_system_auto:linear_system_sparse) = &
                         [spd_auto, spd_dense, spd_banded, path_sparse]

   !> The effective stiffness of one step size.
   type :: level_type
      real(dp) :: h = 0.0_dp               !! step size [s]
      real(dp) :: c0 = 0.0_dp, c1 = 0.0_dp             !! K^ = K + c1 C + c0 M + ...
      real(dp) :: gh = 0.0_dp, g1h = 0.0_dp            !! gamma h, (1 - gamma) h
      real(dp) :: bh2 = 0.0_dp, b2h2 = 0.0_dp          !! beta h^2, (1/2 - beta) h^2
      type(spd_system) :: sys              !! its factored K^ (banded or dense)
      logical :: sparse = .false.          !! K^ is sps instead (fd_sparse, CHOLMOD)
      type(sparse_system) :: sps           !! its factored K^ on the sparse path
      logical :: factored = .false.        !! factored once (then only updated)
      type(woodbury_type) :: wb            !! 'modal' damping's low-rank c1 C in K^ (fd_woodbury)
      integer :: version = -1              !! the pattern of device stiffnesses it holds
   end type level_type

   !> Everything the loop works on, allocated once before it starts. The accepted state (n,
   !> nd, u, v, a, s, f, ag, ag2) is the observer's observed_state, which it extends.
   type, extends(observed_state) :: workspace
      integer :: lmax = 0                             !! halvings below dt2
      real(dp) :: a0 = 0.0_dp, a1c = 0.0_dp           !! C = a0 M + a1c K
      real(dp), allocatable :: mass(:)
      real(dp), allocatable :: mr(:)          !! M r: the load of a unit table acceleration
      type(level_type), allocatable :: lev(:)         !! 1: dt1, 2: dt2, 2 + l: dt2 / 2**l,
                                                      !! lmax + 2 + k: level k of nested refinement
      integer :: nested = 1                           !! levels of the refinement (the paper's: 1)
      integer :: split(max_nested) = 1                !! ratio of level k - 1 to level k (dt1 / dt2 = product)
      integer :: version = 0                          !! counts the accepted phase changes
      real(dp), allocatable :: u1(:), v1(:), a1(:), rhs(:), tmp(:)
      real(dp), allocatable :: sd(:), s1(:), sd1(:), kd(:)
      real(dp), allocatable :: fw(:)                  !! work: the devices' loads of a trial
      ! an accepted step's u1 - u and v + v1 (0:n), 0 at the table's index 0: a spring's ends
      ! without a test for the table (viscous_work)
      real(dp), allocatable :: du(:), vsum(:)
      ! devices between two nodes: the step's loads and relative motion by their nodes, in this
      ! module (pair_loads, pair_motion: three calls to fd_kinematics' kernels a trial cost a
      ! one-device model about 6 % of its instructions); other directions through fd_kinematics
      logical :: pairs = .false.                      !! every device joins two nodes (device_nodes)
      integer, allocatable :: di(:), dj(:)            !! then their nodes (dj = 0: the table)
      type(device_state), allocatable :: st(:), st1(:)
      type(device_state), allocatable :: st0(:)       !! states at the start ('implicit' refinement)
      integer, allocatable :: phase0(:), phase1(:)    !! phases of st, st1 for the observer
      integer, allocatable :: phase_end(:)            !! phases a step is taken for ('implicit')
      logical, allocatable :: changed(:), ok(:)
      ! the devices whose sliding force follows the velocity (a speed-dependent mu)
      integer :: nf = 0                               !! their number
      integer, allocatable :: fl(:)                   !! their device numbers
      real(dp), allocatable :: df(:), cap(:)          !! a pass's change of f0; P mu_largest [N]
      logical :: follow_failed = .false.              !! the trial's forces did not converge
      real(dp) :: follow_misfit = 0.0_dp              !! then its last pass's largest |df| / cap
      integer :: follow_passes = 0                    !! solves the fixed point took in all
      real(dp) :: ag1 = 0.0_dp                        !! the table acceleration at the trial's end
      ! a second horizontal component: its table acceleration now and at the trial state, and
      ! the load M r2 of a unit of it (two = .false.: none)
      logical :: two = .false.
      type(excitation_type) :: exc2
      real(dp) :: ag21 = 0.0_dp
      real(dp), allocatable :: mr2(:)
      ! a vertical component: the bearings' normal forces N = N0 (1 + a_z / g) (three = .false.:
      ! constant); dev holds the devices with p = max(N, 0) at the time normal_forces was
      ! last called for (the laws take it), az that time's a_z
      logical :: three = .false.
      type(excitation_type) :: exc3
      real(dp) :: az = 0.0_dp
      ! the overturning (the model's overturning): each bearing's dN from the floors' inertia
      ! forces at the accepted state (dn) and at the trial's end (dn1); N varies (varies) with
      ! a vertical component or the overturning
      logical :: tilt = .false., varies = .false.
      ! the devices' ks, cs and f0 change only with their phase (N constant, no mu(v), no planar
      ! bearing): a step without a phase change leaves them as they were (device_step)
      logical :: phase_coefficients = .false.
      ! the plan of a trial step, decided at set-up: K^ banded or dense and no low-rank term
      ! (lean: try_step's own calls, else general_product, general_solve); a varying N, mu(v)
      ! or a second component (extras: trial_start, trial_end)
      logical :: lean = .false., extras = .false.
      real(dp), allocatable :: dn(:), dn1(:)          !! per bearing [N]
      ! the bearings on elastic vertical supports under a vertical component (elastic): their
      ! oscillators, advanced over each trial step (fd_vertical_support)
      logical :: elastic = .false.
      type(vertical_support) :: vs
      type(device_type), allocatable :: dev(:)
      real(dp), allocatable :: pn(:)                  !! per bearing: N at the accepted state [N]
      real(dp), allocatable :: nrange(:, :)           !! (2, nd) each device's N extremes at the
                                                      !! dt1 steps, for the step checks [N]
      real(dp) :: w_device = 0.0_dp                   !! work of the device forces [J]
      real(dp) :: t = 0.0_dp                          !! time of the accepted state [s]
      integer :: k = 0                                !! the dt1 step being taken, from k - 1 to k
      type(grid_motion) :: grid                       !! table acceleration at the dt1 steps' ends
      type(observer_type) :: obs                      !! peaks, history, energy balance
      type(ringing_type) :: ring                      !! the sticking springs' ringing
      type(alternation_type) :: alt                   !! the velocity-law bands' alternation
   end type workspace

contains

   !> What Newmark cannot integrate: a device whose law is not regularized (exact Coulomb
   !> friction is set-valued), an excitation type it does not know. Messages name the
   !> group, the variable, the value and what to set.
   subroutine newmark_check(model, exc, error)
      type(model_type), intent(in) :: model         !! the model
      type(excitation_type), intent(in) :: exc      !! the table motion
      type(error_type), allocatable, intent(out) :: error !! what cannot be integrated
      character(len=:), allocatable :: idx, allowed
      integer :: d, law

      do d = 1, model%n_devices
         law = model%dev(d)%law
         if (technique_integrates(technique_newmark, law)) cycle
         idx = 'law('//trim(fmt_int(d))//')'
         call law_choices(allowed, regularized=.true.)
         call fatal_error(error, "group &friction: "//idx//" = '"//trim(law_name(law))//"' is invalid with "// &
                          "technique = '"//trim(technique_name(technique_newmark))//"' of &integration: '"// &
                          trim(law_name(law))//"' is exact (set-valued) friction, which Newmark cannot integrate; "// &
                          "set technique = '"//trim(technique_name(technique_event_driven))//"' (a few devices, "// &
                          "exact event times) or '"//trim(technique_name(technique_moreau_jean))//"' (many devices, "// &
                          "first order in time) in &integration, or "//idx//" to a regularized law: "//allowed)
         return
      end do
      if (exc%kind < 1 .or. exc%kind > size(excitation_types)) then
         call fatal_error(error, "group &excitation: excitation_type (id "//trim(fmt_int(exc%kind))// &
                          ") is not a table motion the Newmark technique knows")
      end if
   end subroutine newmark_check

   !> Integrate a model under a table motion and fill the result. With a control: the
   !> history columns and destinations it selects, stop requests and progress reports.
   subroutine run_newmark(model, exc, opts, res, error, ctl, exc2, exc3)
      type(model_type), intent(in) :: model         !! validated model
      type(excitation_type), intent(in) :: exc      !! validated table motion
      type(integration_type), intent(in) :: opts    !! validated settings
      type(result_type), intent(out) :: res         !! histories and summary
      type(error_type), allocatable, intent(out) :: error !! singular system, divergence, stop
      type(run_control), intent(inout), target, optional :: ctl !! the run's control
      type(excitation_type), intent(in), optional :: exc2 !! a second horizontal component, along
                                                          !! the model's influence2 (kind none: none)
      type(excitation_type), intent(in), optional :: exc3 !! the vertical component: the bearings'
                                                          !! normal forces (kind none: none)
      type(workspace) :: w
      real(dp) :: dt1, dt2
      integer :: c0, c1, crate, l

      call system_clock(c0, crate)
      ! the set-up and the loop in a block left on an error: the sparse factors are CHOLMOD's
      ! (C memory), freed below on every way out
      run: block
         call newmark_check(model, exc, error)
         if (allocated(error)) exit run
         dt1 = exc%dt_record/opts%n1
         dt2 = dt1/opts%n2
         res%newmark%ran = .true.
         associate (st => res%newmark%setup)
            st%dt1 = dt1
            st%dt2 = dt2
            st%dt_min = opts%dt_min
            if (st%dt_min <= 0.0_dp) st%dt_min = dt2/2.0_dp**10
            ! gamma > 1/2 damps; the average acceleration rule's energy residual is round-off
            st%damping_method = opts%gamma > 0.5_dp
            st%exact_accounting = opts%beta == 0.25_dp .and. opts%gamma == 0.5_dp
         end associate
         call setup(model, opts, dt1, dt2, halving_levels(dt2, res%newmark%setup%dt_min), w, res, error)
         if (allocated(error)) exit run
         call second_table_motion(model, .true., w%two, w%exc2, w%mr2, error, exc2)
         if (allocated(error)) exit run
         if (present(exc3)) then
            w%three = exc3%kind /= excitation_none
            if (w%three) w%exc3 = exc3
         end if
         w%tilt = model%overturning
         w%varies = w%three .or. w%tilt
         w%phase_coefficients = .not. (w%varies .or. w%nf > 0 .or. any(w%dev%partner > 0))
         w%extras = w%varies .or. w%nf > 0 .or. w%two
         call observer_init(model, exc, opts, res%newmark%setup%period_stuck, res, w%obs, error, ctl)
         if (allocated(error)) exit run
         if (w%three) then
            call support_setup(w%nd, model%dev, size(w%lev), w%vs, l)
            if (l /= 0) then
               call fatal_error(error, "not enough memory for the vertical supports of the bearings", stat_no_memory)
               exit run
            end if
            w%elastic = w%vs%nb > 0
         end if
         call grid_init(exc, dt1, w%grid)
         call time_loop(model, exc, opts, dt1, w, res, error)
      end block run
      if (allocated(w%lev)) then
         do l = 1, size(w%lev)
            call sparse_free(w%lev(l)%sps)
         end do
      end if
      if (allocated(error)) return
      call system_clock(c1)
      res%run_time = real(c1 - c0, dp)/real(max(crate, 1), dp)
   end subroutine run_newmark

   !> The initial state, run_newmark's time-step loop over the dt1 steps and the run's end
   !> (the step checks' verdicts, the energy balance, the factors' statistics) in the
   !> workspace w that run_newmark set up.
   subroutine time_loop(model, exc, opts, dt1, w, res, error)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      type(integration_type), intent(in) :: opts
      real(dp), intent(in) :: dt1                   !! the step dt1 [s]
      type(workspace), intent(inout) :: w
      type(result_type), intent(inout) :: res
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: t0, ek_v, ep_v
      integer :: k, l
      logical :: any_changed, any_bad, stop, settled

      ! initial state: devices from the initial conditions, acceleration from equilibrium
      w%u = model%u0
      w%v = model%v0
      call device_kinematics(model, w%u, w%v, w%s, w%sd)
      if (w%tilt) call start_overturning(model, exc, w)
      call normal_forces(model, 0.0_dp, w, .false.)
      if (w%varies) call observe_bearing_forces(res, model, 0.0_dp, 0.0_dp, w%az, w%tilt, w%vs, w%pn, w%dn)
      call friction_init(w%dev, w%s, w%sd, w%st, error)
      if (allocated(error)) return
      ! the devices' forces, kept from here on by device_step
      w%f = device_force(w%st, w%s, w%sd)
      if (w%three) call normal_extremes(model, dt1, w, error)
      if (allocated(error)) return
      call ringing_init(model, dt1, opts%beta, opts%gamma, w%a0, w%a1c, w%ring, res, error, w%nrange)
      if (allocated(error)) return
      call alternation_init(model, dt1, opts%gamma, w%alt, res, error, w%nrange)
      if (allocated(error)) return
      if (w%varies) call checks_normal_force(model, w, res)
      call consistent_acceleration(model, exc, 0.0_dp, w)
      call observe_start_energies(w%obs, 0.5_dp*sum(w%mass*w%v**2), strain_energy(model, w%u), &
                                  device_energy(w%dev, w%st, w%s), stored_energies(w%dev, w%st, w%s))
      w%phase0 = w%st%phase
      call observe_sample(w%obs, res, 0.0_dp, w%ag, w%u, w%v, w%a, w%s, w%sd, w%f, w%phase0, ag2=w%ag2)
      call observe_peaks(res, 0.0_dp, w%observed_state)

      do k = 1, w%obs%nsteps
         t0 = (k - 1)*dt1
         w%k = k
         call try_step(model, exc, t0, 1, w, error)
         if (allocated(error)) return
         call judge(opts, w, any_changed, any_bad)
         if (w%nd == 0 .or. .not. (any_changed .or. (any_bad .and. opts%check))) then
            call accept(model, exc, t0 + dt1, w, res, any_changed, .false.)
            res%newmark%steps_dt1 = res%newmark%steps_dt1 + 1
         else if (opts%refinement == refinement_implicit .and. any_changed) then
            ! redone in the phases it ends in; refined as the paper's when they do not settle
            call settle_phases(model, exc, opts, t0, w, res, settled, error)
            if (allocated(error)) return
            if (.not. settled) then
               call advance_nested(model, exc, opts, t0, 0, w, res, error)
               if (allocated(error)) return
            end if
         else if (opts%n2 == 1 .and. .not. (any_bad .and. opts%check)) then
            ! redone as one step of dt2 = dt1 from the same state and phases: the trial itself
            call accept(model, exc, t0 + dt1, w, res, any_changed, any_bad)
            res%newmark%steps_dt2 = res%newmark%steps_dt2 + 1
         else
            call advance_nested(model, exc, opts, t0, 0, w, res, error)
            if (allocated(error)) return
         end if
         if (sample_due(w%obs, k)) then
            if (.not. all(ieee_is_finite(w%u)) .or. .not. all(ieee_is_finite(w%a))) then
               call fatal_error(error, "the solution is not finite at t = "//trim(fmt_real(k*dt1))// &
                                " s: the integration diverged (check beta, gamma and the step)")
               return
            end if
            w%phase0 = w%st%phase
            call observe_sample(w%obs, res, k*dt1, w%ag, w%u, w%v, w%a, w%s, w%sd, w%f, w%phase0, ag2=w%ag2)
         end if
         call observe_poll(w%obs, k*dt1, stop)
         if (stop) then
            call observe_stop_error(w%obs, error)
            return
         end if
      end do
      w%phase0 = w%st%phase
      call ringing_finish(w%ring, w%phase0, res)
      call alternation_finish(model, dt1, opts%gamma, w%alt, res, error)
      if (allocated(error)) return
      res%newmark%mu_passes = w%follow_passes
      ! the vertical supports' energies beside the structure's (0 at the start: at rest)
      call support_energy(w%vs, ek_v, ep_v)
      call observe_end_energies(w%obs, res, 0.5_dp*sum(w%mass*w%v**2) + ek_v, strain_energy(model, w%u) + ep_v, &
                                device_energy(w%dev, w%st, w%s), &
                              w%w_device, stored_energies(w%dev, w%st, w%s))
      do l = 1, size(w%lev)
         res%newmark%factorizations = res%newmark%factorizations + w%lev(l)%sps%factorizations
         res%newmark%factor_updates = res%newmark%factor_updates + w%lev(l)%sps%changes
         associate (stats => w%lev(l)%sys%stats)
            res%newmark%factorizations = res%newmark%factorizations + stats%factorizations
            res%newmark%partial_factorizations = res%newmark%partial_factorizations + stats%partial
            res%newmark%factor_updates = res%newmark%factor_updates + stats%updates + stats%downdates
         end associate
      end do
   end subroutine time_loop

   !> The effective stiffness systems (one set up, copied for every step size; factored when
   !> first used) and the workspace. Memory linear in the number of DOFs and devices.
   subroutine setup(model, opts, dt1, dt2, lmax, w, res, error)
      type(model_type), intent(in) :: model
      type(integration_type), intent(in) :: opts
      real(dp), intent(in) :: dt1, dt2
      integer, intent(in) :: lmax
      type(workspace), intent(inout) :: w
      type(result_type), intent(inout) :: res
      type(error_type), allocatable, intent(out) :: error
      type(spd_system) :: base
      real(dp) :: a0, a1, b, g, h
      integer :: n, nd, l, path, stat, kb
      integer :: none(0)
      logical :: sparse

      n = model%n_dof
      nd = model%n_devices
      w%n = n
      w%nd = nd
      allocate (w%mass(n), w%mr(n), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the masses of n_dof = "//trim(fmt_int(n))//" DOFs", &
                          stat_no_memory)
         return
      end if
      w%mass = model%mass
      do l = 1, n
         w%mr(l) = model%mass(l)*influence_of(model, l)
      end do
      call structure_damping(model, a0, a1, res%newmark%setup%period_stuck, res%newmark%setup%xi_stuck, error)
      if (allocated(error)) return
      w%a0 = a0
      w%a1c = a1
      path = spd_auto
      if (opts%linear_system >= lbound(solver_path, 1) .and. opts%linear_system <= ubound(solver_path, 1)) &
         path = solver_path(opts%linear_system)
      call choose_sparse(model, a0, a1, path, sparse, kb, error)
      if (allocated(error)) return
      if (sparse) then
         res%newmark%storage = 3
         res%newmark%bandwidth = kb
      else
         call spd_setup(base, model%mass, model%spring_i, model%spring_j, model%spring_k, model%dev_ptr, &
                        model%dev_dof, model%dev_coef, error, &
                        a0=a0, a1=a1, path=path, kx_i=model%kx_i, kx_j=model%kx_j, kx_v=model%kx_v)
         if (allocated(error)) return
         res%newmark%storage = merge(1, 2, spd_is_dense(base))
         res%newmark%bandwidth = spd_bandwidth(base)
      end if
      w%lmax = lmax
      ! the levels of the refinement: the paper's is one, dt1 to dt2 = dt1 / n2
      w%nested = 0
      if (opts%refinement == refinement_nested) call nested_splits(opts%n2, w%split, w%nested)
      if (w%nested == 0) then
         w%nested = 1
         w%split(1) = opts%n2
      end if
      allocate (w%lev(lmax + 2 + w%nested - 1), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the effective stiffness of n_dof = "//trim(fmt_int(n))// &
                          " DOFs", stat_no_memory)
         return
      end if
      b = opts%beta
      g = opts%gamma
      do l = 1, size(w%lev)
         if (l == 1) then
            h = dt1
         else if (l <= lmax + 2) then
            h = dt2/2.0_dp**(l - 2)
         else
            h = dt1/real(product(w%split(1:l - lmax - 2)), dp)
         end if
         w%lev(l)%h = h
         w%lev(l)%c0 = 1.0_dp/(b*h*h); w%lev(l)%c1 = g/(b*h)
         w%lev(l)%gh = g*h; w%lev(l)%g1h = (1.0_dp - g)*h
         w%lev(l)%bh2 = b*h*h; w%lev(l)%b2h2 = (0.5_dp - b)*h*h
         w%lev(l)%sparse = sparse
         if (sparse) then
            call sparse_setup(w%lev(l)%sps, model%mass, model%spring_i, model%spring_j, model%spring_k, &
                              model%dev_ptr, model%dev_dof, model%dev_coef, a0, a1, none, none, [real(dp) ::], &
                              error, model%kx_i, model%kx_j, model%kx_v)
         else
            call spd_copy(base, w%lev(l)%sys, error)
         end if
         if (allocated(error)) return
         if (allocated(model%modal_d)) call woodbury_setup(w%lev(l)%wb, model%modal_u, model%modal_d, w%lev(l)%c1, error)
         if (allocated(error)) return
      end do
      allocate (w%u(n), w%v(n), w%a(n), w%u1(n), w%v1(n), w%a1(n), w%rhs(n), w%tmp(n), &
                w%s(nd), w%sd(nd), w%s1(nd), w%sd1(nd), w%f(nd), w%fw(nd), w%kd(nd), w%st(nd), w%st1(nd), w%st0(nd), &
                w%phase0(nd), w%phase1(nd), w%phase_end(nd), w%changed(nd), w%ok(nd), w%di(nd), w%dj(nd), &
                w%du(0:n), w%vsum(0:n), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the state of n_dof = "//trim(fmt_int(n))//" DOFs", &
                          stat_no_memory)
         return
      end if
      w%du(0) = 0.0_dp
      w%vsum(0) = 0.0_dp
      call device_nodes(model, w%di, w%dj, l)
      w%pairs = l == 0
      w%lean = .not. (sparse .or. allocated(model%modal_d))
      w%nf = count(follows_velocity(model%dev))
      allocate (w%fl(w%nf), w%df(w%nf), w%cap(w%nf), w%dev(nd), w%pn(nd), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the state of n_devices = "//trim(fmt_int(nd))//" devices", &
                          stat_no_memory)
         return
      end if
      w%fl = pack([(l, l=1, nd)], follows_velocity(model%dev))
      w%cap = friction_capacity(model%dev(w%fl))
      w%dev = model%dev(1:nd)
      if (model%overturning) then
         allocate (w%dn(size(model%ot_dev)), w%dn1(size(model%ot_dev)), stat=stat)
         if (stat /= 0) then
            call fatal_error(error, "not enough memory for the normal forces of "//trim(fmt_int(nd/2))//" bearings", &
                             stat_no_memory)
            return
         end if
      end if
   end subroutine setup

   !> The overturning's dN at the start: the floors' absolute accelerations those of the table
   !> (the structure at rest relative to it: its acceleration is not known before the friction
   !> forces, which take N).
   subroutine start_overturning(model, exc, w)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      type(workspace), intent(inout) :: w
      real(dp) :: ag2

      ag2 = 0.0_dp
      if (w%two) ag2 = table_acceleration(w%exc2, 0.0_dp)
      w%a1 = 0.0_dp
      call overturning_forces(model, w%a1, table_acceleration(exc, 0.0_dp), ag2, w%dn)
      w%dn1 = w%dn
   end subroutine start_overturning

   !> A vertical component: each bearing's normal force at t, N = N0 (1 + a_z(t) / g) (a_z
   !> upward positive; the vertical support rigid), plus the overturning's dN (fd_overturning:
   !> of the accepted state at a step's start, of the trial state at its end, trial), into w%dev's
   !> p as max(N, 0) for the laws (fd_friction_planar), and the followed devices' capacities
   !> P mu_largest with it (kept while lifted). Nothing when N is constant.
   subroutine normal_forces(model, t, w, trial)
      type(model_type), intent(in) :: model
      real(dp), intent(in) :: t
      type(workspace), intent(inout) :: w
      logical, intent(in) :: trial                 !! t ends the trial step (a1, ag1, ag21 its state)
      real(dp) :: cap
      integer :: d, q, b

      if (.not. w%varies) return
      if (w%three) w%az = table_acceleration(w%exc3, t)
      if (w%tilt) then
         if (trial) call overturning_forces(model, w%a1, w%ag1, w%ag21, w%dn1)
         do b = 1, size(model%ot_dev)
            d = model%ot_dev(b)
            if (trial) then
               call with_normal_force(model%dev(d), w%az, w%dev(d), w%dn1(b))
               call with_normal_force(model%dev(d + 1), w%az, w%dev(d + 1), w%dn1(b))
            else
               call with_normal_force(model%dev(d), w%az, w%dev(d), w%dn(b))
               call with_normal_force(model%dev(d + 1), w%az, w%dev(d + 1), w%dn(b))
            end if
         end do
      else
         call devices_at_normal_force(w%nd, model%dev, w%az, w%dev)
      end if
      ! the bearings on elastic supports: their oscillators' N at t (the trial's end: trial)
      if (w%elastic) then
         if (.not. w%tilt) then
            call support_forces(w%vs, merge(1.0_dp, 0.0_dp, trial), w%nd, w%dev)
         else if (trial) then
            call support_forces(w%vs, 1.0_dp, w%nd, w%dev, w%dn1)
         else
            call support_forces(w%vs, 0.0_dp, w%nd, w%dev, w%dn)
         end if
      end if
      do q = 1, w%nf
         cap = friction_capacity(w%dev(w%fl(q)))
         if (cap > 0.0_dp) w%cap(q) = cap
      end do
   end subroutine normal_forces

   !> A vertical component: each device's smallest and largest normal force at the dt1 steps'
   !> ends (w%nrange), the step checks' (fd_stick_ringing, fd_band_alternation).
   subroutine normal_extremes(model, dt1, w, error)
      type(model_type), intent(in) :: model
      real(dp), intent(in) :: dt1
      type(workspace), intent(inout) :: w
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: az, lo, hi
      integer :: k, stat

      lo = table_acceleration(w%exc3, 0.0_dp)
      hi = lo
      do k = 1, w%obs%nsteps
         az = table_acceleration(w%exc3, k*dt1)
         lo = min(lo, az)
         hi = max(hi, az)
      end do
      allocate (w%nrange(2, w%nd), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the normal forces of n_devices = "//trim(fmt_int(w%nd))// &
                          " devices", stat_no_memory)
         return
      end if
      call normal_force_range(w%nd, model%dev, lo, hi, w%nrange)
   end subroutine normal_extremes

   !> The step checks' N ranges joined with the bearings' N observed so far (the prediction
   !> before the run is a vertical component's alone: the overturning's dN is known as the run
   !> goes): fd_stick_ringing's springs and margins, fd_band_alternation's floors.
   subroutine checks_normal_force(model, w, res)
      type(model_type), intent(in) :: model
      type(workspace), intent(inout) :: w
      type(result_type), intent(inout) :: res

      if (w%ring%n > 0) call ringing_normal_force(model, w%ring, res)
      if (w%alt%n > 0) call alternation_normal_force(model, w%alt, res)
   end subroutine checks_normal_force

   !> Acceleration in equilibrium with the current phases: M a = p - C v - K u - sum b F
   !> (F: the devices' forces kept in w%f).
   subroutine consistent_acceleration(model, exc, t, w)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      real(dp), intent(in) :: t
      type(workspace), intent(inout) :: w
      real(dp) :: xg, vg
      integer :: d

      call table_motion(exc, t, xg, vg, w%ag)
      w%rhs = -w%mr*w%ag
      if (w%two) then
         call table_motion(w%exc2, t, xg, vg, w%ag2)
         w%rhs = w%rhs - w%mr2*w%ag2
      end if
      if (w%lev(1)%sparse) then
         call sparse_c_matvec(w%lev(1)%sps, w%v, w%rhs, -1.0_dp, 1.0_dp)
         call sparse_k_matvec(w%lev(1)%sps, w%u, w%rhs, -1.0_dp, 1.0_dp)
      else
         call spd_c_matvec(w%lev(1)%sys, w%v, w%rhs, -1.0_dp, 1.0_dp)
         if (allocated(model%modal_d)) call lowrank_matvec(model%modal_u, model%modal_d, w%v, w%rhs, -1.0_dp)
         call spd_k_matvec(w%lev(1)%sys, w%u, w%rhs, -1.0_dp, 1.0_dp)
      end if
      do d = 1, w%nd
         call add_device(model, d, -w%f(d), w%rhs)
      end do
      w%a = w%rhs/w%mass
   end subroutine consistent_acceleration

   !> One Newmark step of the size of level lv from t with the current phases, into the
   !> trial state. Acceleration form: with the predictors u~ = u + h v + (1/2 - beta) h^2 a
   !> and v~ = v + (1 - gamma) h a,
   !>   (M + gamma h C_t + beta h^2 K_t) a1 = p1 - F0 - C_t v~ - K_t u~,
   !> solved as K^ a1 = c0 (...) (K^ = c0 (M + ...)); u1 = u~ + beta h^2 a1, v1 = v~ + gamma h a1.
   !> The solve's error is relative to a1 itself (the incremental form's is relative to
   !> c0 du ~ v / (beta h), large at small steps): rank-one updates of the factor keep the
   !> equilibrium at round-off.
   subroutine try_step(model, exc, t, lv, w, error)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      real(dp), intent(in) :: t
      integer, intent(in) :: lv
      type(workspace), intent(inout), target :: w
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: h, ag1

      ! (a level's version is the loop's only once it is factored)
      if (w%lev(lv)%version /= w%version) then
         call factor_for(model, lv, w, error)
         if (allocated(error)) return
      end if
      ! the level by association: w%lev(lv) would load its array descriptor at every use
      associate (lev => w%lev(lv))
         h = lev%h
         if (lv == 1) then
            ! a dt1 step ends at k dt1 (w%k), a point of the grid
            call grid_acceleration(exc, w%grid, w%k, t + h, ag1)
         else
            ag1 = table_acceleration(exc, t + h)
         end if
         w%ag1 = ag1
         call predict(w%n, h, lev%g1h, lev%b2h2, ag1, w%mr, w%u, w%v, w%a, w%tmp, w%u1, w%rhs)
         if (w%extras) call trial_start(model, t, h, w)
         if (w%lean) then
            call spd_kc_matvec(lev%sys, w%u1, w%tmp, w%rhs, -1.0_dp)
         else
            call general_product(model, lv, w)
         end if
         if (w%pairs) then
            call pair_loads(w%n, w%nd, w%di, w%dj, w%st, w%u1, w%tmp, lev%c0, w%rhs)
         else
            call device_loads(model, w%n, w%nd, w%st, w%u1, w%tmp, lev%c0, w%rhs, w%s1, w%sd1, w%fw)
         end if
         if (w%lean) then
            call spd_solve(lev%sys, w%rhs, error)
         else
            call general_solve(model, lv, w, error)
         end if
         if (allocated(error)) return
         call correct(w%n, lev%bh2, lev%gh, w%rhs, w%tmp, w%a1, w%u1, w%v1)
         if (w%pairs) then
            call pair_motion(w%n, w%nd, w%di, w%dj, w%u1, w%v1, w%s1, w%sd1)
         else
            call relative_motion(model, w%n, w%nd, w%u1, w%v1, w%s1, w%sd1)
         end if
      end associate
      if (w%extras) call trial_end(model, t, h, lv, w, error)
   end subroutine try_step

   !> A trial's start beyond the lean step (w%extras), after the predictors: the normal forces
   !> of the step's start (the follow's; of its end for the laws' update: trial_end), a
   !> speed-dependent mu's sliding forces from the velocity at the step's start (whatever an
   !> earlier trial of the step left in them: follow_forces takes them on), and the second
   !> component's load at the step's end t + h.
   subroutine trial_start(model, t, h, w)
      type(model_type), intent(in) :: model
      real(dp), intent(in) :: t, h
      type(workspace), intent(inout) :: w

      if (w%varies) call normal_forces(model, t, w, .false.)
      if (w%nf > 0) call start_forces(w%dev, w)
      if (w%two) then
         w%ag21 = table_acceleration(w%exc2, t + h)
         w%rhs = w%rhs - w%mr2*w%ag21
      end if
   end subroutine trial_start

   !> A trial's product K u~ + C v~ off the lean path: K^ sparse (CHOLMOD) or banded, 'modal'
   !> damping's low-rank term.
   subroutine general_product(model, lv, w)
      type(model_type), intent(in) :: model
      integer, intent(in) :: lv
      type(workspace), intent(inout) :: w

      associate (lev => w%lev(lv))
         if (lev%sparse) then
            call sparse_kc_matvec(lev%sps, w%u1, w%tmp, w%rhs, -1.0_dp)
         else
            call spd_kc_matvec(lev%sys, w%u1, w%tmp, w%rhs, -1.0_dp)
         end if
         if (lev%wb%r > 0) call lowrank_matvec(model%modal_u, model%modal_d, w%tmp, w%rhs, -1.0_dp)
      end associate
   end subroutine general_product

   !> A trial's solve off the lean path (general_product's): the solution a1 in w%rhs.
   subroutine general_solve(model, lv, w, error)
      type(model_type), intent(in) :: model
      integer, intent(in) :: lv
      type(workspace), intent(inout) :: w
      type(error_type), allocatable, intent(out) :: error

      associate (lev => w%lev(lv))
         if (lev%sparse) then
            call sparse_solve(lev%sps, w%rhs, error)
         else
            call spd_solve(lev%sys, w%rhs, error)
         end if
         if (allocated(error)) return
         if (lev%wb%r > 0) call woodbury_correct(lev%wb, model%modal_u, w%rhs)
      end associate
   end subroutine general_solve

   !> A trial's end beyond the lean step (w%extras): a speed-dependent mu's forces iterated to
   !> the step's end, the vertical supports' trial from the accepted state at t (a_z linear in
   !> the step), the normal forces at the step's end t + h.
   subroutine trial_end(model, t, h, lv, w, error)
      type(model_type), intent(in) :: model
      real(dp), intent(in) :: t, h
      integer, intent(in) :: lv
      type(workspace), intent(inout) :: w
      type(error_type), allocatable, intent(out) :: error

      if (w%nf > 0) call follow_forces(model, lv, w, error)
      if (w%elastic) call support_advance(w%vs, lv, t + h, table_acceleration(w%exc3, t), table_acceleration(w%exc3, t + h))
      if (w%varies) call normal_forces(model, t + h, w, .true.)
   end subroutine trial_end

   !> A speed-dependent mu at the velocity at the step's end (implicit, as a Newton-Raphson
   !> code's trial takes it): the sliding forces f0 of the devices that follow the velocity are
   !> iterated to the step's fixed point f0 = P mu(|s'1(f0)|) sgn. The trial is affine in each
   !> f0, so a pass adds the change df along b_d to the load, solves with the step's factor
   !> (nothing is refactored) and moves the trial state by the solution. It contracts by about
   !> rho = P |dmu/dv| gamma h / m_r a pass (the x of the slope's dashpot P dmu/dv: rho >= 1 is
   !> where the step would leave it alternating). Converged when no |df| exceeds follow_tol
   !> P mu_largest. When a pass does not shrink the misfit enough to reach that within
   !> max_follow passes (rho above about 0.6: a mu too steep for the step), the trial goes
   !> back to the forces it started with (mu at the velocity at the step's start,
   !> start_forces) and w%follow_failed is set: the step is then refined, and counted if it
   !> is accepted so.
   subroutine follow_forces(model, lv, w, error)
      type(model_type), intent(in) :: model
      integer, intent(in) :: lv
      type(workspace), intent(inout), target :: w
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: misfit, last
      integer :: it, q

      w%follow_failed = .false.
      last = huge(1.0_dp)
      do it = 0, max_follow
         call friction_follow(w%nf, w%fl, w%dev, w%sd1, w%st, w%df)
         misfit = 0.0_dp
         do q = 1, w%nf
            if (abs(w%df(q)) > follow_tol*w%cap(q)) misfit = max(misfit, abs(w%df(q))/w%cap(q))
         end do
         if (misfit == 0.0_dp) return
         ! the contraction of the last pass, kept up, would not bring the misfit below
         ! follow_tol within the passes left (or it does not contract at all)
         if (it == max_follow .or. .not. misfit < last) exit
         if (it > 0 .and. misfit*(misfit/last)**(max_follow - it) > follow_tol) exit
         last = misfit
         call move_forces(model, lv, w, error)
         if (allocated(error)) return
      end do
      ! back to the trial with the forces it started with, mu at the step's start (start_forces)
      w%follow_failed = .true.
      w%follow_misfit = misfit
      call friction_follow(w%nf, w%fl, w%dev, w%sd, w%st, w%df)
      call move_forces(model, lv, w, error)
   end subroutine follow_forces

   !> The followed devices' f0 at the relative velocities at the step's start (w%sd): the
   !> first guess of the fixed point, and what an unconverged step keeps.
   subroutine start_forces(dev, w)
      type(device_type), intent(in) :: dev(:)
      type(workspace), intent(inout) :: w
      integer :: q

      call friction_follow(w%nf, w%fl, dev, w%sd, w%st, w%df)
      do q = 1, w%nf
         w%st(w%fl(q))%f0 = w%st(w%fl(q))%f0 + w%df(q)
      end do
   end subroutine start_forces

   !> The trial state with the followed devices' f0 changed by w%df: the change of the load
   !> along each b_d solved with the step's factor, the state moved by the solution.
   subroutine move_forces(model, lv, w, error)
      type(model_type), intent(in) :: model
      integer, intent(in) :: lv
      type(workspace), intent(inout), target :: w
      type(error_type), allocatable, intent(out) :: error
      integer :: q, d, i

      do i = 1, w%n
         w%rhs(i) = 0.0_dp
      end do
      do q = 1, w%nf
         d = w%fl(q)
         w%st(d)%f0 = w%st(d)%f0 + w%df(q)
         call add_device(model, d, -(w%lev(lv)%c0*w%df(q)), w%rhs)
      end do
      if (w%lev(lv)%sparse) then
         call sparse_solve(w%lev(lv)%sps, w%rhs, error)
      else
         call spd_solve(w%lev(lv)%sys, w%rhs, error)
      end if
      if (allocated(error)) return
      if (w%lev(lv)%wb%r > 0) call woodbury_correct(w%lev(lv)%wb, model%modal_u, w%rhs)
      w%follow_passes = w%follow_passes + 1
      do i = 1, w%n
         w%a1(i) = w%a1(i) + w%rhs(i)
         w%u1(i) = w%u1(i) + w%lev(lv)%bh2*w%rhs(i)
         w%v1(i) = w%v1(i) + w%lev(lv)%gh*w%rhs(i)
      end do
      call device_kinematics(model, w%u1, w%v1, w%s1, w%sd1)
   end subroutine move_forces

   !> Predictors v~ = v + (1 - gamma) h a (in vt), u~ = u + h v + (1/2 - beta) h^2 a (in ut),
   !> and the table's inertia load -M r ag1 (in rhs).
   pure subroutine predict(n, h, g1h, b2h2, ag1, mass, u, v, a, vt, ut, rhs)
      integer, intent(in) :: n
      real(dp), intent(in) :: h, g1h, b2h2, ag1
      real(dp), intent(in) :: mass(n)   !! M r, the load of a unit table acceleration
      real(dp), intent(in) :: u(n), v(n), a(n)
      real(dp), intent(out) :: vt(n), ut(n), rhs(n)
      integer :: i

      !GCC$ ivdep
      do i = 1, n
         vt(i) = v(i) + g1h*a(i)
         ut(i) = u(i) + (h*v(i) + b2h2*a(i))
         rhs(i) = -mass(i)*ag1
      end do
   end subroutine predict

   !> The devices' forces at the predictors, F = ks s~ + cs s'~ + f0, subtracted from rhs
   !> along b_d; then rhs scaled by c0 (K^ = c0 (M + gamma h C_t + beta h^2 K_t)).
   pure subroutine device_loads(model, n, nd, st, ut, vt, c0, rhs, s, sd, f)
      type(model_type), intent(in) :: model
      integer, intent(in) :: n, nd
      type(device_state), intent(in) :: st(nd)
      real(dp), intent(in) :: ut(n), vt(n), c0
      real(dp), intent(inout) :: rhs(n)
      real(dp), intent(out) :: s(nd), sd(nd), f(nd)   !! work: s~, s'~ and -F of each device
      integer :: d, i

      call relative_motion(model, n, nd, ut, vt, s, sd)
      do d = 1, nd
         f(d) = -(st(d)%ks*s(d) + st(d)%cs*sd(d) + st(d)%f0)
      end do
      call device_forces(model, n, nd, f, rhs)
      do i = 1, n
         rhs(i) = c0*rhs(i)
      end do
   end subroutine device_loads

   !> device_loads for devices that all join two nodes (b_d = e_i - e_j, e_i to the table): the
   !> forces at the predictors subtracted from rhs by the nodes, then rhs scaled by c0. The same
   !> operations in the same order as device_loads, so the same results to the bit.
   pure subroutine pair_loads(n, nd, di, dj, st, ut, vt, c0, rhs)
      integer, intent(in) :: n, nd
      integer, intent(in) :: di(nd), dj(nd)
      type(device_state), intent(in) :: st(nd)
      real(dp), intent(in) :: ut(n), vt(n), c0
      real(dp), intent(inout) :: rhs(n)
      real(dp) :: f
      integer :: d, i, j

      do d = 1, nd
         i = di(d)
         j = dj(d)
         if (j > 0) then
            f = st(d)%ks*(ut(i) - ut(j)) + st(d)%cs*(vt(i) - vt(j)) + st(d)%f0
            rhs(j) = rhs(j) + f
         else
            f = st(d)%ks*ut(i) + st(d)%cs*vt(i) + st(d)%f0
         end if
         rhs(i) = rhs(i) - f
      end do
      do i = 1, n
         rhs(i) = c0*rhs(i)
      end do
   end subroutine pair_loads

   !> relative_motion for devices that all join two nodes: s = u_i - u_j, s' = v_i - v_j
   !> (u_i, v_i to the table).
   pure subroutine pair_motion(n, nd, di, dj, u1, v1, s1, sd1)
      integer, intent(in) :: n, nd
      integer, intent(in) :: di(nd), dj(nd)
      real(dp), intent(in) :: u1(n), v1(n)
      real(dp), intent(out) :: s1(nd), sd1(nd)
      integer :: d, i, j

      do d = 1, nd
         i = di(d)
         j = dj(d)
         if (j > 0) then
            s1(d) = u1(i) - u1(j)
            sd1(d) = v1(i) - v1(j)
         else
            s1(d) = u1(i)
            sd1(d) = v1(i)
         end if
      end do
   end subroutine pair_motion

   !> The trial state from a1 (in rhs): u1 = u~ + beta h^2 a1, v1 = v~ + gamma h a1.
   pure subroutine correct(n, bh2, gh, a1s, vt, a1, u1, v1)
      integer, intent(in) :: n
      real(dp), intent(in) :: bh2, gh
      real(dp), intent(in) :: a1s(n), vt(n)
      real(dp), intent(out) :: a1(n), v1(n)
      real(dp), intent(inout) :: u1(n)
      integer :: i

      !GCC$ ivdep
      do i = 1, n
         a1(i) = a1s(i)
         u1(i) = u1(i) + bh2*a1s(i)
         v1(i) = vt(i) + gh*a1s(i)
      end do
   end subroutine correct

   !> Whether K^ goes to the sparse path (fd_sparse, CHOLMOD): asked for, or, with 'auto', when
   !> a step there costs less than on the band (docs/theory.md, section 10.7): a step solves
   !> with the factor and multiplies by K and C, 6 n (kb + 1) entries read on the band of
   !> half-width kb after reverse Cuthill-McKee ordering, 2 nnz(L) + 4 nnz(K^) sparse (nnz(L)
   !> from CHOLMOD's symbolic analysis, made only when kb > auto_band), each sparse entry
   !> costing sparse_weight band entries (indirect indexing). kb: the band.
   subroutine choose_sparse(model, a0, a1, path, sparse, kb, error)
      type(model_type), intent(in) :: model
      real(dp), intent(in) :: a0, a1
      integer, intent(inout) :: path
      logical, intent(out) :: sparse
      integer, intent(out) :: kb
      type(error_type), allocatable, intent(out) :: error
      type(sparse_system) :: probe
      integer :: none(0)
      real(dp) :: banded_cost, sparse_cost

      sparse = .false.
      kb = 0
      if (path == path_sparse) then
         if (.not. sparse_available()) then
            call fatal_error(error, "&integration: linear_system = 'sparse' needs the sparse solver, and this build has &
                             &no CHOLMOD (SuiteSparse): use 'auto' or 'banded', or rebuild with libsuitesparse-dev")
         else if (allocated(model%modal_d)) then
            call fatal_error(error, "&integration: linear_system = 'sparse' does not take damping = 'modal' (its &
                             &low-rank term goes with the banded factor): use 'auto' or 'banded'")
         else
            sparse = .true.
            kb = sparse_band(model%n_dof, model%spring_i, model%spring_j, model%dev_ptr, model%dev_dof, none, none, &
                             model%kx_i, model%kx_j)
         end if
         return
      end if
      if (path /= spd_auto .or. allocated(model%modal_d) .or. model%n_dof <= spd_dense_max_n) return
      if (.not. sparse_available()) return
      kb = sparse_band(model%n_dof, model%spring_i, model%spring_j, model%dev_ptr, model%dev_dof, none, none, &
                       model%kx_i, model%kx_j)
      if (kb <= auto_band) return
      call sparse_setup(probe, model%mass, model%spring_i, model%spring_j, model%spring_k, model%dev_ptr, &
                        model%dev_dof, model%dev_coef, a0, a1, none, none, [real(dp) ::], error, model%kx_i, &
                        model%kx_j, model%kx_v)
      if (allocated(error)) then
         call sparse_free(probe)
         return
      end if
      banded_cost = 6.0_dp*real(model%n_dof, dp)*real(kb + 1, dp)
      sparse_cost = 2.0_dp*sparse_factor_entries(probe) + 4.0_dp*real(sparse_nonzeros(probe), dp)
      call sparse_free(probe)
      sparse = sparse_weight*sparse_cost < banded_cost
      if (sparse) path = path_sparse
   end subroutine choose_sparse

   !> The factored effective stiffness of level lv for the current phases: factored the
   !> first time the level is used, updated (never refactored from scratch) when the
   !> devices' stiffnesses have changed since it was last used; with 'modal' damping, the
   !> Woodbury factors of its low-rank term follow the factor. try_step calls it when the
   !> level's version is not the loop's.
   subroutine factor_for(model, lv, w, error)
      type(model_type), intent(in) :: model
      integer, intent(in) :: lv
      type(workspace), intent(inout), target :: w
      type(error_type), allocatable, intent(out) :: error
      integer :: d

      associate (lev => w%lev(lv))
         do d = 1, w%nd
            w%kd(d) = w%st(d)%ks + lev%c1*w%st(d)%cs
         end do
         if (lev%sparse .and. .not. lev%factored) then
            call sparse_factor(lev%sps, lev%c0, lev%c1, w%kd, error)
            lev%factored = .not. allocated(error)
         else if (lev%sparse) then
            call sparse_update_devices(lev%sps, w%kd, error)
         else if (.not. lev%factored) then
            call spd_factor(lev%sys, lev%c0, lev%c1, w%kd, error)
            lev%factored = .not. allocated(error)
         else
            call spd_update_devices(lev%sys, w%kd, error)
         end if
         if (.not. allocated(error) .and. lev%wb%r > 0) call woodbury_factor(lev%wb, model%modal_u, lev%sys, error)
         if (allocated(error)) then
            error%message = "the step "//trim(fmt_real(lev%h))//" s: "//error%message
            return
         end if
         lev%version = w%version
      end associate
   end subroutine factor_for

   !> Phases after the trial step, and the correctness condition of the step (with the
   !> convergence of a speed-dependent mu's forces).
   subroutine judge(opts, w, any_changed, any_bad)
      type(integration_type), intent(in) :: opts
      type(workspace), intent(inout) :: w
      logical, intent(out) :: any_changed, any_bad

      call friction_step(w%nd, w%dev, opts%n_corr, w%s1, w%sd1, w%sd, w%st, w%st1, w%changed, w%ok, &
                         any_changed, any_bad)
      ! a speed-dependent mu whose forces did not converge in the step: refined as a violation
      any_bad = any_bad .or. w%follow_failed
   end subroutine judge

   !> The refinement: cover the piece [t, t + h_k] of level k (0: the dt1 step), whose own
   !> trial step changed a phase or violated the correctness condition, with the split(k + 1)
   !> pieces of level k + 1. The last level is dt2, whose pieces advance_refined covers (the
   !> paper's refinement has only that level: n2 steps dt2). The pieces of an intermediate
   !> level (nested refinement) are each tried as one step and accepted when no device
   !> changes phase (nor violates the condition, when checked); else split again.
   recursive subroutine advance_nested(model, exc, opts, t, k, w, res, error)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      type(integration_type), intent(in) :: opts
      real(dp), intent(in) :: t                  !! start of the piece [s]
      integer, intent(in) :: k                   !! its level
      type(workspace), intent(inout) :: w
      type(result_type), intent(inout) :: res
      type(error_type), allocatable, intent(out) :: error
      integer :: j, lv
      real(dp) :: h, tj
      logical :: any_changed, any_bad, stop

      if (k + 1 == w%nested) then
         lv = 2
      else
         lv = w%lmax + 2 + k + 1
      end if
      h = w%lev(lv)%h
      do j = 1, w%split(k + 1)
         tj = t + (j - 1)*h
         if (lv == 2) then
            call advance_refined(model, exc, opts, tj, h, w, res, error)
            if (allocated(error)) return
            cycle
         end if
         call try_step(model, exc, tj, lv, w, error)
         if (allocated(error)) return
         call judge(opts, w, any_changed, any_bad)
         if (any_changed .or. (any_bad .and. opts%check)) then
            call advance_nested(model, exc, opts, tj, k + 1, w, res, error)
            if (allocated(error)) return
         else
            call accept(model, exc, tj + h, w, res, any_changed, any_bad)
            res%newmark%steps_nested = res%newmark%steps_nested + 1
            call observe_poll(w%obs, tj + h, stop)
            if (stop) then
               call observe_stop_error(w%obs, error)
               return
            end if
         end if
      end do
   end subroutine advance_nested

   !> Cover [t, t + sub] with steps sub, sub/2, ... down to dt_min, halving while the
   !> correctness condition fails (when the check is on).
   subroutine advance_refined(model, exc, opts, t, sub, w, res, error)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      type(integration_type), intent(in) :: opts
      real(dp), intent(in) :: t, sub
      type(workspace), intent(inout) :: w
      type(result_type), intent(inout) :: res
      type(error_type), allocatable, intent(out) :: error
      integer :: lmax, level, pos, units, d
      real(dp) :: h, tl
      logical :: any_changed, any_bad, stop

      lmax = w%lmax
      units = 2**lmax
      pos = 0
      level = 0
      do while (pos < units)
         h = w%lev(2 + level)%h
         tl = t + sub*real(pos, dp)/real(units, dp)
         call try_step(model, exc, tl, 2 + level, w, error)
         if (allocated(error)) return
         call judge(opts, w, any_changed, any_bad)
         if (any_bad .and. opts%check .and. level < lmax) then
            level = level + 1
            cycle
         end if
         if (any_bad .and. opts%check) then
            ! a violation left at dt_min: an error when the band is below what dt_min resolves
            ! (fd_step_limits), else counted
            do d = 1, w%nd
               if (w%ok(d)) cycle
               call unresolved_band(model, d, tl + h, res%newmark%setup%dt_min, error)
               if (allocated(error)) return
            end do
         end if
         call accept(model, exc, tl + h, w, res, any_changed, any_bad)
         if (level == 0) then
            res%newmark%steps_dt2 = res%newmark%steps_dt2 + 1
         else
            res%newmark%steps_finer = res%newmark%steps_finer + 1
         end if
         call observe_poll(w%obs, tl + h, stop)
         if (stop) then
            call observe_stop_error(w%obs, error)
            return
         end if
         pos = pos + 2**(lmax - level)
         do while (level > 0)
            if (mod(pos, 2**(lmax - level + 1)) /= 0) exit
            level = level - 1
         end do
      end do
   end subroutine advance_refined

   !> `refinement = 'implicit'`: the dt1 step from t, whose trial in the phases at its start
   !> ended with a phase change, taken in the phases it ends in (an active-set iteration, as a
   !> Newton-Raphson code resolves an elastic-perfectly-plastic link; a transition is located
   !> to within dt1, not dt2). Each law says in which state a step that ends in a phase is
   !> taken (friction_settle: a hysteretic slide that starts, in its sliding force; one that
   !> ends within the band, in the slide, the force continuous at its end; a velocity-law
   !> device in its end phase's coefficients; a reversal through the band, of either law, is
   !> not taken in one phase). The step is redone in those states
   !> until the phases at its end, judged from the states at its start, are those it was taken
   !> for. It is accepted when they are, the states it was taken in lead to the same phases
   !> at its end, and (checked) no device that keeps its phase violates the correctness
   !> condition; its transitions are counted from the phases at the start. Otherwise (a change
   !> no single phase takes, a second change at the end, a violation, phases back to those
   !> at the start, or max_settle trials) the start is restored and settled is .false.: the
   !> caller refines the step as the paper does. A trial updates the dt1 factor for the
   !> devices whose stiffness or damping differs (spd_update_devices: rank-one updates, or a
   !> refactorization from the first changed column), never a full refactorization.
   subroutine settle_phases(model, exc, opts, t, w, res, settled, error)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      type(integration_type), intent(in) :: opts
      real(dp), intent(in) :: t
      type(workspace), intent(inout) :: w
      type(result_type), intent(inout) :: res
      logical, intent(out) :: settled
      type(error_type), allocatable, intent(out) :: error
      logical :: any_changed, any_bad, can, redone
      integer :: it, d

      settled = .false.
      redone = .false.
      w%st0 = w%st
      w%phase0 = w%st0%phase
      do it = 1, max_settle
         ! the phases at the end of the last trial, and the states to take the step in
         w%phase_end = w%st1%phase
         call friction_settle(w%nd, w%dev, w%sd1, w%st0, w%st1, w%st, can)
         if (.not. can) exit
         if (it > 1 .or. .not. same_phases(w%nd, w%st, w%phase0)) then
            w%version = w%version + 1
            redone = .true.
            call try_step(model, exc, t, 1, w, error)
            if (allocated(error)) return
            res%newmark%implicit_redos = res%newmark%implicit_redos + 1
            ! the phases this trial ends in, judged from the start
            call friction_step(w%nd, w%dev, opts%n_corr, w%s1, w%sd1, w%sd, w%st0, w%st1, w%changed, w%ok, &
                               any_changed, any_bad)
            if (.not. any_changed) exit
            if (.not. same_phases(w%nd, w%st1, w%phase_end)) cycle
         end if
         ! from the states the step was taken in, the same phases at its end; the condition in
         ! the devices that keep their phase through the step (it is a condition inside a
         ! phase: a changing device's velocities at the two ends belong to different phases)
         call judge(opts, w, any_changed, any_bad)
         if (.not. same_phases(w%nd, w%st1, w%phase_end)) exit
         any_bad = w%follow_failed
         do d = 1, w%nd
            if (w%phase_end(d) /= w%phase0(d)) w%ok(d) = .true.
            any_bad = any_bad .or. .not. w%ok(d)
         end do
         if (any_bad .and. opts%check) exit
         ! transitions at the start (a slide that starts), then those at the end (in accept)
         w%phase1 = w%st%phase
         call observe_transitions(res, w%phase0, w%phase1)
         call accept(model, exc, t + w%lev(1)%h, w, res, any_changed, any_bad)
         res%newmark%steps_implicit = res%newmark%steps_implicit + 1
         settled = .true.
         return
      end do
      ! the start's states again; a factor that a redone trial updated follows them back
      w%st = w%st0
      if (redone) w%version = w%version + 1
      res%newmark%implicit_fallbacks = res%newmark%implicit_fallbacks + 1
   end subroutine settle_phases

   !> Every device's phase in st is phase.
   pure logical function same_phases(nd, st, phase) result(same)
      integer, intent(in) :: nd
      type(device_state), intent(in) :: st(nd)
      integer, intent(in) :: phase(nd)
      integer :: d

      same = .true.
      do d = 1, nd
         if (st(d)%phase /= phase(d)) then
            same = .false.
            return
         end if
      end do
   end function same_phases

   !> Make the trial state the current one: phases, counters, energy, peaks.
   subroutine accept(model, exc, t1, w, res, any_changed, any_bad)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      real(dp), intent(in) :: t1
      type(workspace), intent(inout) :: w
      type(result_type), intent(inout) :: res
      logical, intent(in) :: any_changed         !! a device changed phase
      logical, intent(in) :: any_bad             !! a device violates the correctness condition
      real(dp) :: ein
      logical :: changed_k, any_force

      ! energy of the step, forces at both ends in the step's phases; the state moves on
      call step_energy(w%n, w%mr, w%u, w%v, w%a, w%u1, w%v1, w%a1, w%du, w%vsum, ein)
      ein = 0.5_dp*(w%ag + w%ag1)*ein
      if (w%two) then
         ein = ein + 0.5_dp*(w%ag2 + w%ag21)*dot_product(w%mr2, w%du(1:))
         w%ag2 = w%ag21
      end if
      call observe_work(res, -ein, 0.5_dp*viscous_work(model, w%a0, w%a1c, w%n, w%mass, w%du, w%vsum))
      w%ag = w%ag1
      ! violations of the correctness condition left in an accepted step
      if (any_bad) call observe_violations(res, t1, w%ok)
      if (any_changed) then
         w%phase0 = w%st%phase
         w%phase1 = w%st1%phase
         call observe_transitions(res, w%phase0, w%phase1)
      end if
      ! device work over the step; the devices move on; the factors follow their stiffness
      ! and damping (whatever changed them); after a phase change, or a sliding force that
      ! follows the velocity (mu(v)), the next step starts in equilibrium with the new forces
      call device_step(w%nd, w%st, w%st1, w%s, w%sd, w%s1, w%sd1, w%f, w%w_device, w%obs%device_work, &
                       w%obs%slip_travel, any_changed .or. .not. w%phase_coefficients, changed_k, any_force)
      ! the sticking springs' ringing: the step joins its phases' statistics (fd_stick_ringing)
      if (w%ring%n > 0) then
         call phase_statistics(w%nd, t1 - w%t, w%st, w%sd, w%f, w%ring%stats)
         if (any_changed) call ringing_changed(w%ring, w%phase0, w%phase1, res)
      end if
      ! the velocity-law bands' forces: an alternation from step to step (fd_band_alternation)
      if (w%alt%n > 0) call alternation_step(w%alt, w%nd, t1 - w%t, w%st, w%f, res%band_alternation, &
                                             res%band_alternation_time)
      if (w%extras) call accept_extras(model, t1, w, res)
      w%t = t1
      if (changed_k) w%version = w%version + 1
      ! (a varying normal force changes a band's dashpot or a sticking spring within a phase)
      if (any_changed .or. any_force .or. (w%varies .and. changed_k)) call consistent_acceleration(model, exc, t1, w)
      call observe_peaks(res, t1, w%observed_state)
   end subroutine accept

   !> An accepted step's part beyond the lean step (w%extras), before the state's time moves to
   !> t1: a speed-dependent mu's forces that did not converge in it, counted; a varying N (a
   !> vertical component or the overturning, tilt; an elastic support comes with a vertical
   !> component): the vertical supports move on, the bearings' forces, the step checks' N ranges.
   subroutine accept_extras(model, t1, w, res)
      type(model_type), intent(in) :: model
      real(dp), intent(in) :: t1
      type(workspace), intent(inout) :: w
      type(result_type), intent(inout) :: res

      if (w%follow_failed) then
         res%mu_unconverged = res%mu_unconverged + 1
         if (res%mu_unconverged == 1) res%mu_unconverged_time = t1
         res%mu_misfit = max(res%mu_misfit, w%follow_misfit)
      end if
      if (.not. w%varies) return
      if (w%tilt) w%dn = w%dn1
      if (w%elastic) then
         ! the ground's work on the vertical supports and their dashpots'
         call support_accept(w%vs)
         call observe_work(res, w%vs%w_in1, w%vs%w_damp1)
      end if
      call observe_bearing_forces(res, model, t1, t1 - w%t, w%az, w%tilt, w%vs, w%pn, w%dn)
      call checks_normal_force(model, w, res)
   end subroutine accept_extras

   !> The state moves to the trial state; du = u1 - u (in du(1:n)), v + v1 (in vsum(1:n)) and
   !> sum_i m_i r_i du_i (the input work's factor) of the step.
   pure subroutine step_energy(n, mass, u, v, a, u1, v1, a1, du, vsum, ein)
      integer, intent(in) :: n
      real(dp), intent(in) :: mass(n)   !! M r
      real(dp), intent(in) :: u1(n), v1(n), a1(n)
      real(dp), intent(inout) :: u(n), v(n), a(n)
      real(dp), intent(inout) :: du(0:n), vsum(0:n)   !! index 0 (the table) left as it is
      real(dp), intent(out) :: ein
      integer :: i

      ein = 0.0_dp
      do i = 1, n
         du(i) = u1(i) - u(i)
         vsum(i) = v(i) + v1(i)
         ein = ein + mass(i)*du(i)
         u(i) = u1(i)
         v(i) = v1(i)
         a(i) = a1(i)
      end do
   end subroutine step_energy

   !> (v + v1)' C du of a step, C = a0 M + a1 K, K from the springs and K_x (no matrix product),
   !> and 'modal' damping's low-rank term. The springs' du' K vsum is summed here, not by
   !> fd_stiffness' stiffness_form: at every accepted step the call cost a two-mass model 5 % of
   !> its instructions.
   pure real(dp) function viscous_work(model, a0, a1, n, mass, du, vsum) result(e)
      type(model_type), intent(in) :: model
      real(dp), intent(in) :: a0, a1
      integer, intent(in) :: n
      real(dp), intent(in) :: mass(n)
      real(dp), intent(in) :: du(0:n), vsum(0:n)   !! 0 at index 0: a spring's end at the table
      real(dp) :: ek
      integer :: i, s

      e = 0.0_dp
      if (a0 /= 0.0_dp) then
         do i = 1, n
            e = e + mass(i)*vsum(i)*du(i)
         end do
         e = a0*e
      end if
      if (a1 /= 0.0_dp) then
         ek = 0.0_dp
         ! (an end at the table, index 0, subtracts 0 or is subtracted from 0: the values of
         ! a spring's (u_i - u_j) alone)
         do s = 1, model%n_springs
            ek = ek + model%spring_k(s)*(du(model%spring_i(s)) - du(model%spring_j(s)))* &
                 (vsum(model%spring_i(s)) - vsum(model%spring_j(s)))
         end do
         if (model%n_kx > 0) ek = ek + general_form(model, du(1:n), vsum(1:n))
         e = e + a1*ek
      end if
      if (allocated(model%modal_d)) e = e + lowrank_form(model%modal_u, model%modal_d, vsum(1:n), du(1:n))
   end function viscous_work

   !> Work of the device forces over the step (trapezoid, the step's phases), in all and per
   !> device, and each device's slip travel (|ds| in a step taken sliding), added to the
   !> observer's totals here, in the loop over the devices (a call a step would cost more
   !> than the sums); the devices move
   !> on to the trial state (s, s', state) and their force in it; whether a stiffness or
   !> damping changed, and whether a constant force f0 changed (compared only when they may
   !> have: compare).
   pure subroutine device_step(nd, st, st1, s, sd, s1, sd1, f, w, work, travel, compare, changed_k, changed_f0)
      integer, intent(in) :: nd
      type(device_state), intent(inout) :: st(nd)
      type(device_state), intent(in) :: st1(nd)
      real(dp), intent(inout) :: s(nd), sd(nd)
      real(dp), intent(in) :: s1(nd), sd1(nd)
      real(dp), intent(inout) :: f(nd)         !! in: the forces at the start (the step's phases: set
                                               !! by the last call, or at the start of the run); out:
                                               !! at the end, in the phases for the next step
      real(dp), intent(inout) :: w
      real(dp), intent(inout) :: work(nd), travel(nd) !! per device: work [J], slip travel [m]
      logical, intent(in) :: compare           !! a phase changed, or coefficients change within one
      logical, intent(out) :: changed_k, changed_f0
      real(dp) :: f0, f1, dw
      integer :: d

      changed_k = .false.
      changed_f0 = .false.
      do d = 1, nd
         f0 = f(d)
         f1 = st(d)%ks*s1(d) + st(d)%cs*sd1(d) + st(d)%f0
         dw = 0.5_dp*(f0 + f1)*(s1(d) - s(d))
         w = w + dw
         work(d) = work(d) + dw
         if (st(d)%phase /= phase_stick) travel(d) = travel(d) + abs(s1(d) - s(d))
         s(d) = s1(d)
         sd(d) = sd1(d)
         if (compare) then
            changed_k = changed_k .or. st1(d)%ks /= st(d)%ks .or. st1(d)%cs /= st(d)%cs
            changed_f0 = changed_f0 .or. st1(d)%f0 /= st(d)%f0
         end if
         st(d) = st1(d)
         f(d) = st(d)%ks*s(d) + st(d)%cs*sd(d) + st(d)%f0
      end do
   end subroutine device_step

   !> An accepted step of length h joins the statistics of the devices' phases
   !> (fd_stick_ringing's stats): its length, s'^2 h and |F| at its end (after a change of
   !> phase, the new phase's force: P mu when a stick phase ends in a slide), and cs h (cs of
   !> the phase it ends in). Here, beside the step, so that it is inlined.
   pure subroutine phase_statistics(nd, h, st, sd, f, stats)
      integer, intent(in) :: nd
      real(dp), intent(in) :: h
      type(device_state), intent(in) :: st(nd)
      real(dp), intent(in) :: sd(nd), f(nd)
      real(dp), intent(inout) :: stats(4, nd)
      integer :: d

      do d = 1, nd
         stats(stat_time, d) = stats(stat_time, d) + h
         stats(stat_sd2, d) = stats(stat_sd2, d) + sd(d)*sd(d)*h
         stats(stat_fmax, d) = max(stats(stat_fmax, d), abs(f(d)))
         stats(stat_damping, d) = stats(stat_damping, d) + st(d)%cs*h
      end do
   end subroutine phase_statistics

   !> Strain energy of the structure, 1/2 u' K u: the springs' sum_s k_s (u_i - u_j)^2 / 2 (no
   !> cancellation) and K_x's.
   pure real(dp) function strain_energy(model, u) result(e)
      type(model_type), intent(in) :: model
      real(dp), intent(in) :: u(:)

      e = 0.5_dp*stiffness_form(model, u, u)
   end function strain_energy

   !> Elastic energy stored in the devices (each law's: fd_friction's friction_energy).
   pure real(dp) function device_energy(dev, st, s) result(e)
      type(device_type), intent(in) :: dev(:)   !! the devices at the current normal forces
      type(device_state), intent(in) :: st(:)
      real(dp), intent(in) :: s(:)

      e = sum(stored_energies(dev, st, s))
   end function device_energy

   !> Each device's elastic energy at the current normal forces (dev's p): a bearing's force
   !> without its pendulum's excess (fd_friction_planar's pendulum_excess, at s: its f0 took
   !> it at the s of the state's update), which is the pendulum's, not the friction's.
   pure function stored_energies(dev, st, s) result(e)
      type(device_type), intent(in) :: dev(:)
      type(device_state), intent(in) :: st(:)
      real(dp), intent(in) :: s(:)
      real(dp) :: e(size(st))
      type(device_state) :: one
      real(dp) :: kp
      integer :: d

      do d = 1, size(st)
         one = st(d)
         kp = pendulum_excess(dev(d))
         if (kp /= 0.0_dp) one%f0 = one%f0 - kp*s(d)
         e(d) = friction_energy(dev(d), one, s(d))
      end do
   end function stored_energies

end module fd_newmark
