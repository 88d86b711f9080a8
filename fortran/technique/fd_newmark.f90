!> The time-step loop: Newmark integration (average acceleration by default) of
!>   M u'' + C u' + K u + sum_d b_d F_d = -M r x0''(t)
!> with the paper's two step sizes: dt1 = dt_record / n1, and a step in which any friction
!> device changes phase is redone from its start with n2 steps dt2 = dt1 / n2. A step that
!> violates the correctness condition (eqs. 9, 12) is redone with dt2 and then by halving
!> down to dt_min; a violation left at the floor is counted and reported, never hidden.
!>
!> In each phase a device is linear, F = ks s + cs s' + f0, so a step solves one linear
!> system with the effective stiffness K + ks.. + (gamma/(beta h)) (C + cs..) + M/(beta h^2).
!> Its Cholesky factor is kept in a small cache keyed by the step size and the pattern of
!> sticking devices: it is factored again only when one of them changes.
module fd_newmark
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_real, fmt_int, stat_no_memory
   use fd_names, only: laws, law_name, law_choices, excitation_types, technique_name, technique_newmark, &
                       technique_event_driven
   use fd_model, only: model_type, integration_type
   use fd_excitation, only: excitation_type, table_motion
   use fd_matrices, only: structure_matrices
   use fd_kinematics, only: device_kinematics, device_relative, add_device
   use fd_linalg, only: cholesky_factor, cholesky_solve, sym_matvec
   use fd_device_state, only: device_state, device_force
   use fd_friction, only: friction_init, friction_update, friction_correct
   use fd_result, only: result_type
   use fd_observer, only: observer_type, observer_init, sample_due, observe_start, observe_peaks, &
                          observe_sample, observe_transitions, observe_violations, observe_end
   use fd_step_limits, only: halving_levels, unresolved_band
   implicit none
   private

   public :: run_newmark, newmark_check

   integer, parameter :: max_slots = 32              !! factors kept at most
   real(dp), parameter :: cache_bytes = 256.0e6_dp    !! memory the factors may take

   !> One cached factor of the effective stiffness.
   type :: factor_slot
      real(dp) :: h = -1.0_dp              !! step size it was made for
      logical, allocatable :: stuck(:)     !! devices with ks or cs in the matrix
      real(dp), allocatable :: a(:, :)     !! Cholesky factor
      integer :: last_use = 0              !! for least-recently-used replacement
   end type factor_slot

   !> Everything the loop works on, allocated once before it starts.
   type :: workspace
      integer :: n = 0, nd = 0, clock = 0
      real(dp), allocatable :: mass(:), k(:, :), c(:, :)
      real(dp), allocatable :: u(:), v(:), a(:), u1(:), v1(:), a1(:), rhs(:), tmp(:)
      real(dp), allocatable :: s(:), sd(:), s1(:), sd1(:), f(:)
      type(device_state), allocatable :: st(:), st1(:)
      integer, allocatable :: phase0(:), phase1(:)    !! phases of st, st1 for the observer
      logical, allocatable :: changed(:), ok(:), stuck(:)
      real(dp) :: ag = 0.0_dp, ag1 = 0.0_dp
      real(dp) :: w_device = 0.0_dp                   !! work of the device forces [J]
      type(observer_type) :: obs                      !! peaks, history, energy balance
      type(factor_slot), allocatable :: slot(:)
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
         if (law >= 1 .and. law <= size(laws)) then
            if (laws(law)%regularized) cycle
         end if
         idx = 'law('//trim(fmt_int(d))//')'
         call law_choices(allowed, regularized=.true.)
         call fatal_error(error, "group &friction: "//idx//" = '"//trim(law_name(law))//"' is invalid with "// &
                          "technique = '"//trim(technique_name(technique_newmark))//"' of &integration: '"// &
                          trim(law_name(law))//"' is exact (set-valued) friction, which Newmark cannot integrate; "// &
                          "set technique = '"//trim(technique_name(technique_event_driven))//"' in &integration, "// &
                          "or "//idx//" to a regularized law: "//allowed)
         return
      end do
      if (exc%kind < 1 .or. exc%kind > size(excitation_types)) then
         call fatal_error(error, "group &excitation: excitation_type (id "//trim(fmt_int(exc%kind))// &
                          ") is not a table motion the Newmark technique knows")
      end if
   end subroutine newmark_check

   !> Integrate a model under a table motion and fill the result.
   subroutine run_newmark(model, exc, opts, res, error)
      type(model_type), intent(in) :: model         !! validated model
      type(excitation_type), intent(in) :: exc      !! validated table motion
      type(integration_type), intent(in) :: opts    !! validated settings
      type(result_type), intent(out) :: res         !! histories and summary
      type(error_type), allocatable, intent(out) :: error !! singular system, divergence
      type(workspace) :: w
      real(dp) :: dt1, dt2, t0
      integer :: k, j, c0, c1, crate
      logical :: any_changed, any_bad

      call system_clock(c0, crate)
      call newmark_check(model, exc, error)
      if (allocated(error)) return
      dt1 = exc%dt_record/opts%n1
      dt2 = dt1/opts%n2
      res%dt1 = dt1
      res%dt2 = dt2
      res%dt_min = opts%dt_min
      if (res%dt_min <= 0.0_dp) res%dt_min = dt2/2.0_dp**10
      call setup(model, halving_levels(dt2, res%dt_min), w, res, error)
      if (allocated(error)) return
      call observer_init(model, exc, opts, res, w%obs, error)
      if (allocated(error)) return

      ! initial state: devices from the initial conditions, acceleration from equilibrium
      w%u = model%u0
      w%v = model%v0
      call device_kinematics(model, w%u, w%v, w%s, w%sd)
      call friction_init(model%dev, w%s, w%sd, w%st, error)
      if (allocated(error)) return
      call consistent_acceleration(model, exc, 0.0_dp, w)
      call observe_start(w%obs, w%mass, w%k, w%u, w%v, device_energy(w%st, w%s), w%rhs)
      w%f = device_force(w%st, w%s, w%sd)
      w%phase0 = w%st%phase
      call observe_sample(w%obs, res, 0.0_dp, w%ag, w%u, w%v, w%a, w%s, w%sd, w%f, w%phase0)
      call observe_peaks(res, 0.0_dp, w%u, w%v, w%a, w%ag, w%s, w%f)

      do k = 1, w%obs%nsteps
         t0 = (k - 1)*dt1
         call try_step(model, exc, opts, t0, dt1, w, res, error)
         if (allocated(error)) return
         call judge(model, opts, w, any_changed, any_bad)
         if (w%nd == 0 .or. .not. (any_changed .or. (any_bad .and. opts%check))) then
            call accept(model, exc, t0 + dt1, w, res, .false.)
            res%steps_dt1 = res%steps_dt1 + 1
         else
            do j = 1, opts%n2
               call advance_refined(model, exc, opts, t0 + (j - 1)*dt2, dt2, res%dt_min, w, res, error)
               if (allocated(error)) return
            end do
         end if
         if (sample_due(w%obs, k)) then
            if (.not. all(ieee_is_finite(w%u)) .or. .not. all(ieee_is_finite(w%a))) then
               call fatal_error(error, "the solution is not finite at t = "//trim(fmt_real(k*dt1))// &
                                " s: the integration diverged (check beta, gamma and the step)")
               return
            end if
            w%f = device_force(w%st, w%s, w%sd)
            w%phase0 = w%st%phase
            call observe_sample(w%obs, res, k*dt1, w%ag, w%u, w%v, w%a, w%s, w%sd, w%f, w%phase0)
         end if
      end do
      call observe_end(w%obs, res, w%mass, w%k, w%u, w%v, device_energy(w%st, w%s), w%w_device, w%rhs)
      call system_clock(c1)
      res%run_time = real(c1 - c0, dp)/real(max(crate, 1), dp)
   end subroutine run_newmark

   !> Matrices and workspace. The factor cache holds the
   !> step sizes dt1, dt2, dt2/2, ... dt_min with two phase patterns each when memory allows.
   subroutine setup(model, lmax, w, res, error)
      type(model_type), intent(in) :: model
      integer, intent(in) :: lmax
      type(workspace), intent(inout) :: w
      type(result_type), intent(inout) :: res
      type(error_type), allocatable, intent(out) :: error
      integer :: n, nd, i, n_slots, stat

      n = model%n_dof
      nd = model%n_devices
      w%n = n
      w%nd = nd
      allocate (w%mass(n), w%k(n, n), w%c(n, n), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the matrices of n_dof = "//trim(fmt_int(n))//" DOFs", &
                          stat_no_memory)
         return
      end if
      w%mass = model%mass
      call structure_matrices(model, w%k, w%c, res%period_stuck, res%xi_stuck, error)
      if (allocated(error)) return
      allocate (w%u(n), w%v(n), w%a(n), w%u1(n), w%v1(n), w%a1(n), w%rhs(n), w%tmp(n), &
                w%s(nd), w%sd(nd), w%s1(nd), w%sd1(nd), w%f(nd), w%st(nd), w%st1(nd), w%phase0(nd), w%phase1(nd), &
                w%changed(nd), w%ok(nd), w%stuck(nd), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the state of n_dof = "//trim(fmt_int(n))//" DOFs", &
                          stat_no_memory)
         return
      end if
      n_slots = min(max_slots, 2*(lmax + 2), max(4, int(cache_bytes/(8.0_dp*n*n))))
      if (nd == 0) n_slots = 1
      allocate (w%slot(n_slots), stat=stat)
      do i = 1, n_slots
         if (stat == 0) allocate (w%slot(i)%stuck(nd), w%slot(i)%a(n, n), stat=stat)
         if (stat /= 0) then
            call fatal_error(error, "not enough memory for the factors of n_dof = "//trim(fmt_int(n))//" DOFs", &
                             stat_no_memory)
            return
         end if
      end do
   end subroutine setup


   !> Acceleration in equilibrium with the current phases: M a = p - C v - K u - sum b F.
   subroutine consistent_acceleration(model, exc, t, w)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      real(dp), intent(in) :: t
      type(workspace), intent(inout) :: w
      real(dp) :: xg, vg
      integer :: d

      call table_motion(exc, t, xg, vg, w%ag)
      w%rhs = -w%mass*w%ag
      call sym_matvec(w%c, w%v, w%rhs, -1.0_dp, 1.0_dp)
      call sym_matvec(w%k, w%u, w%rhs, -1.0_dp, 1.0_dp)
      do d = 1, w%nd
         call add_device(model, d, -device_force(w%st(d), w%s(d), w%sd(d)), w%rhs)
      end do
      w%a = w%rhs/w%mass
   end subroutine consistent_acceleration

   !> One Newmark step of size h from t with the current phases, into the trial state.
   subroutine try_step(model, exc, opts, t, h, w, res, error)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      type(integration_type), intent(in) :: opts
      real(dp), intent(in) :: t, h
      type(workspace), intent(inout) :: w
      type(result_type), intent(inout) :: res
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: b, g, c0, c1, c2, c3, c4, c5, xg, vg, proj
      integer :: is, d

      b = opts%beta; g = opts%gamma
      c0 = 1.0_dp/(b*h*h); c1 = g/(b*h); c2 = 1.0_dp/(b*h); c3 = 0.5_dp/b - 1.0_dp
      c4 = g/b - 1.0_dp; c5 = h*(0.5_dp*g/b - 1.0_dp)
      call factor_for(model, h, c0, c1, w, res, is, error)
      if (allocated(error)) return
      call table_motion(exc, t + h, xg, vg, w%ag1)
      ! incremental form, K^ du = p1 - F0 - K u + M (c2 v + c3 a) + C (c4 v + c5 a), so that
      ! a1 = c0 du - c2 v - c3 a does not lose digits to c0 u at small steps
      w%tmp = c4*w%v + c5*w%a
      w%rhs = w%mass*(c2*w%v + c3*w%a - w%ag1)
      call sym_matvec(w%c, w%tmp, w%rhs, 1.0_dp, 1.0_dp)
      call sym_matvec(w%k, w%u, w%rhs, -1.0_dp, 1.0_dp)
      do d = 1, w%nd
         proj = device_relative(model, d, w%tmp)
         call add_device(model, d, w%st(d)%cs*proj - w%st(d)%ks*w%s(d) - w%st(d)%f0, w%rhs)
      end do
      call cholesky_solve(w%slot(is)%a, w%rhs)
      w%u1 = w%u + w%rhs
      w%a1 = c0*w%rhs - c2*w%v - c3*w%a
      w%v1 = w%v + h*((1.0_dp - g)*w%a + g*w%a1)
      call device_kinematics(model, w%u1, w%v1, w%s1, w%sd1)
   end subroutine try_step

   !> The cached factor for step h and the current phase pattern, made if missing.
   subroutine factor_for(model, h, c0, c1, w, res, is, error)
      type(model_type), intent(in) :: model
      real(dp), intent(in) :: h, c0, c1
      type(workspace), intent(inout) :: w
      type(result_type), intent(inout) :: res
      integer, intent(out) :: is
      type(error_type), allocatable, intent(out) :: error
      integer :: i, d, info, ni, nj
      real(dp) :: kd

      w%clock = w%clock + 1
      w%stuck = w%st%ks /= 0.0_dp .or. w%st%cs /= 0.0_dp
      do is = 1, size(w%slot)
         if (w%slot(is)%h == h) then
            if (all(w%slot(is)%stuck .eqv. w%stuck)) then
               w%slot(is)%last_use = w%clock
               return
            end if
         end if
      end do
      is = minloc(w%slot%last_use, 1)
      associate (a => w%slot(is)%a)
         a = w%k + c1*w%c
         do i = 1, w%n
            a(i, i) = a(i, i) + c0*w%mass(i)
         end do
         do d = 1, w%nd
            kd = w%st(d)%ks + c1*w%st(d)%cs
            if (kd == 0.0_dp) cycle
            ni = model%dev(d)%node_i; nj = model%dev(d)%node_j
            a(ni, ni) = a(ni, ni) + kd
            if (nj > 0) then
               a(nj, nj) = a(nj, nj) + kd
               a(ni, nj) = a(ni, nj) - kd
               a(nj, ni) = a(nj, ni) - kd
            end if
         end do
         call cholesky_factor(a, info)
      end associate
      res%factorizations = res%factorizations + 1
      if (info /= 0) then
         w%slot(is)%h = -1.0_dp
         call fatal_error(error, "the effective stiffness for the step "//trim(fmt_real(h))// &
                          " s is not positive definite (leading minor "//trim(fmt_int(info))//")")
         return
      end if
      w%slot(is)%h = h
      w%slot(is)%stuck = w%stuck
      w%slot(is)%last_use = w%clock
   end subroutine factor_for

   !> Phases after the trial step, and the correctness condition of the step.
   subroutine judge(model, opts, w, any_changed, any_bad)
      type(model_type), intent(in) :: model
      type(integration_type), intent(in) :: opts
      type(workspace), intent(inout) :: w
      logical, intent(out) :: any_changed, any_bad

      w%st1 = w%st
      call friction_update(model%dev, w%s1, w%sd1, w%st1, w%changed)
      w%ok = friction_correct(model%dev, opts%n_corr, w%st, w%sd, w%sd1)
      any_changed = any(w%changed)
      any_bad = .not. all(w%ok)
   end subroutine judge

   !> Cover [t, t + sub] with steps sub, sub/2, ... down to dt_min, halving while the
   !> correctness condition fails (when the check is on).
   subroutine advance_refined(model, exc, opts, t, sub, dt_min, w, res, error)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      type(integration_type), intent(in) :: opts
      real(dp), intent(in) :: t, sub, dt_min
      type(workspace), intent(inout) :: w
      type(result_type), intent(inout) :: res
      type(error_type), allocatable, intent(out) :: error
      integer :: lmax, level, pos, units, d
      real(dp) :: h, tl
      logical :: any_changed, any_bad

      lmax = halving_levels(sub, dt_min)
      units = 2**lmax
      pos = 0
      level = 0
      do while (pos < units)
         h = sub/2.0_dp**level
         tl = t + sub*real(pos, dp)/real(units, dp)
         call try_step(model, exc, opts, tl, h, w, res, error)
         if (allocated(error)) return
         call judge(model, opts, w, any_changed, any_bad)
         if (any_bad .and. opts%check .and. level < lmax) then
            level = level + 1
            cycle
         end if
         if (any_bad .and. opts%check) then
            ! a violation left at dt_min: an error when the band is below what dt_min resolves
            ! (fd_step_limits), else counted
            do d = 1, w%nd
               if (w%ok(d)) cycle
               call unresolved_band(model, d, tl + h, dt_min, error)
               if (allocated(error)) return
            end do
         end if
         call accept(model, exc, tl + h, w, res, any_bad)
         if (level == 0) then
            res%steps_dt2 = res%steps_dt2 + 1
         else
            res%steps_finer = res%steps_finer + 1
         end if
         pos = pos + 2**(lmax - level)
         do while (level > 0)
            if (mod(pos, 2**(lmax - level + 1)) /= 0) exit
            level = level - 1
         end do
      end do
   end subroutine advance_refined

   !> Make the trial state the current one: phases, counters, energy, peaks.
   subroutine accept(model, exc, t1, w, res, any_bad)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      real(dp), intent(in) :: t1
      type(workspace), intent(inout) :: w
      type(result_type), intent(inout) :: res
      logical, intent(in) :: any_bad
      integer :: d
      real(dp) :: f0, f1
      logical :: any_force

      ! energy of the step, forces at both ends in the step's phases
      w%tmp = w%u1 - w%u
      res%e_input = res%e_input - 0.5_dp*(w%ag + w%ag1)*sum(w%mass*w%tmp)
      w%rhs = 0.0_dp
      call sym_matvec(w%c, w%tmp, w%rhs, 1.0_dp, 0.0_dp)
      res%e_viscous = res%e_viscous + 0.5_dp*sum((w%v + w%v1)*w%rhs)
      do d = 1, w%nd
         f0 = device_force(w%st(d), w%s(d), w%sd(d))
         f1 = device_force(w%st(d), w%s1(d), w%sd1(d))
         w%w_device = w%w_device + 0.5_dp*(f0 + f1)*(w%s1(d) - w%s(d))
      end do
      ! violations of the correctness condition left in an accepted step
      if (any_bad) call observe_violations(res, t1, w%ok)
      w%phase0 = w%st%phase
      w%phase1 = w%st1%phase
      call observe_transitions(res, w%phase0, w%phase1)
      w%u = w%u1; w%v = w%v1; w%a = w%a1; w%ag = w%ag1
      w%s = w%s1; w%sd = w%sd1
      ! a phase change, or a sliding force that follows the velocity (mu(v)): the next
      ! step starts in equilibrium with the new forces
      any_force = any(w%st1%f0 /= w%st%f0)
      w%st = w%st1
      if (any(w%changed) .or. any_force) call consistent_acceleration(model, exc, t1, w)
      w%f = device_force(w%st, w%s, w%sd)
      call observe_peaks(res, t1, w%u, w%v, w%a, w%ag, w%s, w%f)
   end subroutine accept

   !> Elastic energy stored in devices whose phase has a stiffness (hysteretic sticking).
   pure real(dp) function device_energy(st, s) result(e)
      type(device_state), intent(in) :: st(:)
      real(dp), intent(in) :: s(:)
      integer :: d

      e = 0.0_dp
      do d = 1, size(st)
         if (st(d)%ks > 0.0_dp) e = e + 0.5_dp*st(d)%ks*(s(d) + st(d)%f0/st(d)%ks)**2
      end do
   end function device_energy

end module fd_newmark
