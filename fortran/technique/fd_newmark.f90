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
   use fd_error, only: error_type, fatal_error, fmt_real, fmt_int
   use fd_model, only: model_type, integration_type
   use fd_excitation, only: excitation_type, table_motion
   use fd_matrices, only: structure_matrices
   use fd_linalg, only: cholesky_factor, cholesky_solve, sym_matvec
   use fd_device_state, only: device_state, device_force
   use fd_friction, only: friction_init, friction_update, friction_correct
   use fd_result, only: result_type, max_violation_times, init_result, record_transition
   implicit none
   private

   public :: run_newmark

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
      real(dp), allocatable :: s(:), sd(:), s1(:), sd1(:)
      type(device_state), allocatable :: st(:), st1(:)
      logical, allocatable :: changed(:), ok(:), stuck(:)
      real(dp) :: ag = 0.0_dp, ag1 = 0.0_dp
      real(dp) :: w_device = 0.0_dp, e_device0 = 0.0_dp, e_kin0 = 0.0_dp, e_str0 = 0.0_dp
      type(factor_slot), allocatable :: slot(:)
   end type workspace

contains

   !> Integrate a model under a table motion and fill the result.
   subroutine run_newmark(model, exc, opts, res, error)
      type(model_type), intent(in) :: model         !! validated model
      type(excitation_type), intent(in) :: exc      !! validated table motion
      type(integration_type), intent(in) :: opts    !! validated settings
      type(result_type), intent(out) :: res         !! histories and summary
      type(error_type), allocatable, intent(out) :: error !! singular system, divergence
      type(workspace) :: w
      real(dp) :: dt1, dt2, t0
      integer :: nsteps, every, k, j, iout, c0, c1, crate
      logical :: any_changed, any_bad

      call system_clock(c0, crate)
      dt1 = exc%dt_record/opts%n1
      dt2 = dt1/opts%n2
      res%dt1 = dt1
      res%dt2 = dt2
      res%dt_min = opts%dt_min
      if (res%dt_min <= 0.0_dp) res%dt_min = dt2/2.0_dp**10
      call setup(model, halving_levels(dt2, res%dt_min), w, res, error)
      if (allocated(error)) return
      call init_result(model, exc, opts, res, nsteps, every, error)
      if (allocated(error)) return

      ! initial state: devices from the initial conditions, acceleration from equilibrium
      w%u = model%u0
      w%v = model%v0
      call device_kinematics(model, w%u, w%v, w%s, w%sd)
      call friction_init(model%dev, w%s, w%sd, w%st)
      call consistent_acceleration(model, exc, 0.0_dp, w)
      w%e_device0 = device_energy(w%st, w%s)
      w%e_kin0 = 0.5_dp*sum(w%mass*w%v**2)
      w%e_str0 = strain_energy(w%k, w%u, w%rhs)
      iout = 1
      call sample(model, 0.0_dp, w, res, iout)
      call track_peaks(0.0_dp, w, res)

      do k = 1, nsteps
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
         if (mod(k, every) == 0 .or. k == nsteps) then
            if (.not. all(ieee_is_finite(w%u)) .or. .not. all(ieee_is_finite(w%a))) then
               call fatal_error(error, "the solution is not finite at t = "//trim(fmt_real(k*dt1))// &
                                " s: the integration diverged (check beta, gamma and the step)")
               return
            end if
            iout = iout + 1
            call sample(model, k*dt1, w, res, iout)
         end if
      end do
      call finish_energy(w, res)
      call system_clock(c1)
      res%run_time = real(c1 - c0, dp)/real(max(crate, 1), dp)
   end subroutine run_newmark

   !> Number of halvings from sub down to dt_min.
   pure integer function halving_levels(sub, dt_min) result(lmax)
      real(dp), intent(in) :: sub, dt_min

      lmax = 0
      do while (lmax < 30 .and. sub/2.0_dp**(lmax + 1) >= dt_min*(1.0_dp - 1.0e-12_dp))
         lmax = lmax + 1
      end do
   end function halving_levels

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
      w%mass = model%mass
      allocate (w%k(n, n), w%c(n, n), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the matrices of n_dof = "//trim(fmt_int(n))//" DOFs")
         return
      end if
      call structure_matrices(model, w%k, w%c, res%period_stuck, res%xi_stuck, error)
      if (allocated(error)) return
      allocate (w%u(n), w%v(n), w%a(n), w%u1(n), w%v1(n), w%a1(n), w%rhs(n), w%tmp(n))
      allocate (w%s(nd), w%sd(nd), w%s1(nd), w%sd1(nd), w%st(nd), w%st1(nd))
      allocate (w%changed(nd), w%ok(nd), w%stuck(nd))
      n_slots = min(max_slots, 2*(lmax + 2), max(4, int(cache_bytes/(8.0_dp*n*n))))
      if (nd == 0) n_slots = 1
      allocate (w%slot(n_slots))
      do i = 1, n_slots
         allocate (w%slot(i)%stuck(nd), w%slot(i)%a(n, n), stat=stat)
         if (stat /= 0) then
            call fatal_error(error, "not enough memory for the factors of n_dof = "//trim(fmt_int(n))//" DOFs")
            return
         end if
      end do
   end subroutine setup


   !> Relative displacement and velocity of every device.
   pure subroutine device_kinematics(model, u, v, s, sd)
      type(model_type), intent(in) :: model
      real(dp), intent(in) :: u(:), v(:)
      real(dp), intent(out) :: s(:), sd(:)
      integer :: d, i, j

      do d = 1, model%n_devices
         i = model%dev(d)%node_i; j = model%dev(d)%node_j
         s(d) = u(i); sd(d) = v(i)
         if (j > 0) then
            s(d) = s(d) - u(j); sd(d) = sd(d) - v(j)
         end if
      end do
   end subroutine device_kinematics

   !> Add alpha * b_d to y, b_d = e_i - e_j the direction of device d.
   pure subroutine add_device(model, d, alpha, y)
      type(model_type), intent(in) :: model
      integer, intent(in) :: d
      real(dp), intent(in) :: alpha
      real(dp), intent(inout) :: y(:)
      integer :: i, j

      i = model%dev(d)%node_i; j = model%dev(d)%node_j
      y(i) = y(i) + alpha
      if (j > 0) y(j) = y(j) - alpha
   end subroutine add_device

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
         proj = w%tmp(model%dev(d)%node_i)
         if (model%dev(d)%node_j > 0) proj = proj - w%tmp(model%dev(d)%node_j)
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
      integer :: lmax, level, pos, units
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
      if (any_bad) then
         do d = 1, w%nd
            if (w%ok(d)) cycle
            res%violations = res%violations + 1
            if (res%n_violation_times < max_violation_times) then
               res%n_violation_times = res%n_violation_times + 1
               res%violation_time(res%n_violation_times) = t1
               res%violation_device(res%n_violation_times) = d
            end if
         end do
      end if
      do d = 1, w%nd
         call record_transition(res, d, w%st(d)%phase, w%st1(d)%phase)
      end do
      w%u = w%u1; w%v = w%v1; w%a = w%a1; w%ag = w%ag1
      w%s = w%s1; w%sd = w%sd1
      w%st = w%st1
      if (any(w%changed)) call consistent_acceleration(model, exc, t1, w)
      call track_peaks(t1, w, res)
   end subroutine accept

   subroutine track_peaks(t, w, res)
      real(dp), intent(in) :: t
      type(workspace), intent(in) :: w
      type(result_type), intent(inout) :: res
      integer :: i
      real(dp) :: x

      do i = 1, w%n
         if (abs(w%u(i)) > res%peak_u(i)) then
            res%peak_u(i) = abs(w%u(i)); res%peak_u_time(i) = t
         end if
         res%peak_v(i) = max(res%peak_v(i), abs(w%v(i)))
         x = abs(w%a(i) + w%ag)
         if (x > res%peak_aabs(i)) then
            res%peak_aabs(i) = x; res%peak_aabs_time(i) = t
         end if
      end do
      do i = 1, w%nd
         res%peak_s(i) = max(res%peak_s(i), abs(w%s(i)))
         res%peak_force(i) = max(res%peak_force(i), abs(device_force(w%st(i), w%s(i), w%sd(i))))
      end do
   end subroutine track_peaks

   subroutine sample(model, t, w, res, iout)
      type(model_type), intent(in) :: model
      real(dp), intent(in) :: t
      type(workspace), intent(in) :: w
      type(result_type), intent(inout) :: res
      integer, intent(in) :: iout
      integer :: i, c

      if (iout > res%nout) return
      res%hist(1, iout) = t
      res%hist(2, iout) = w%ag
      c = 2
      do i = 1, w%n
         res%hist(c + 1:c + 3, iout) = [w%u(i), w%v(i), w%a(i) + w%ag]
         c = c + 3
      end do
      do i = 1, model%n_devices
         res%hist(c + 1:c + 4, iout) = [w%s(i), w%sd(i), device_force(w%st(i), w%s(i), w%sd(i)), &
                                        real(w%st(i)%phase, dp)]
         c = c + 4
      end do
   end subroutine sample

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

   !> Strain energy of the springs, 1/2 u K u.
   real(dp) function strain_energy(k, u, tmp) result(e)
      real(dp), intent(in) :: k(:, :), u(:)
      real(dp), intent(inout) :: tmp(:)

      call sym_matvec(k, u, tmp, 1.0_dp, 0.0_dp)
      e = 0.5_dp*dot_product(u, tmp)
   end function strain_energy

   subroutine finish_energy(w, res)
      type(workspace), intent(inout) :: w
      type(result_type), intent(inout) :: res

      res%e_kinetic = 0.5_dp*sum(w%mass*w%v**2) - w%e_kin0
      res%e_strain = strain_energy(w%k, w%u, w%rhs) - w%e_str0
      res%e_device = device_energy(w%st, w%s) - w%e_device0
      res%e_friction = w%w_device - res%e_device
      res%e_residual = res%e_input - (res%e_kinetic + res%e_strain + res%e_viscous + &
                                      res%e_friction + res%e_device)
   end subroutine finish_energy

end module fd_newmark
