!> The exact Coulomb technique: unregularized Coulomb friction with event-driven
!> stick-slip switching (the paper's group (ii), done exactly).
!>
!> A sticking device is a rigid link (s' = 0) carrying whatever force |F| <= P mu keeps it
!> stuck; a sliding device carries F = P mu sgn(s'). Between events each phase pattern is a
!> linear time-invariant system in the reduced coordinates q (u = T q + u_c, one q per group
!> of nodes joined by sticking devices, none for a group holding the table):
!>   x = (q, q'),  x' = A x + b1 + bag ag(t)
!> integrated exactly: x(t + tau) = phi (x - xp(t)) + xp(t + tau) + gam1 (b1 + bag g0) + gam2 bag g1,
!> with the particular solution xp of the harmonic table motion (sum of sines), or the
!> first-order hold of a piecewise-linear recorded acceleration (ag = g0 + g1 tau).
!> Events (a sliding device's s' reaching zero; a sticking device's required force reaching
!> P mu) are located to round-off by Brent's method on the exact solution. At an event the
!> phases are decided from the forces needed to keep the candidate devices stuck: one small
!> least-squares solve for all of them; a device needing more than P mu slides in the
!> direction of that force.
module fd_coulomb
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_real, fmt_int
   use fd_model, only: model_type, integration_type, law_coulomb
   use fd_excitation, only: excitation_type, table_motion, excitation_harmonic, excitation_record
   use fd_matrices, only: structure_matrices, link_groups
   use fd_expm, only: lti_propagators
   use fd_linalg, only: sym_matvec, gen_matvec, lu_solve, least_squares, least_squares_work
   use fd_result, only: result_type, init_result, record_transition
   use fd_device_state, only: phase_stick
   implicit none
   private

   public :: run_coulomb

   real(dp), parameter :: pi = acos(-1.0_dp)
   integer, parameter :: max_freq = 3                       !! sines in the table acceleration
   real(dp), parameter :: gl_x(3) = [0.5_dp - sqrt(0.15_dp), 0.5_dp, 0.5_dp + sqrt(0.15_dp)]
   real(dp), parameter :: gl_w(3) = [5.0_dp/18.0_dp, 8.0_dp/18.0_dp, 5.0_dp/18.0_dp]


   !> Table acceleration on one forcing segment: sum_k amp(k) sin(w(k) t) for harmonic
   !> motion; for a record, linear between samples (handled by the caller).
   type :: forcing_type
      integer :: nf = 0
      real(dp) :: w(max_freq) = 0.0_dp
      real(dp) :: amp(max_freq) = 0.0_dp
   end type forcing_type

   !> The reduced linear system of one phase pattern, and its propagators.
   type :: pattern_type
      integer :: nq = 0, m = 0                       !! reduced DOFs, state size 2 nq
      integer, allocatable :: grp(:)                 !! group of each DOF (0 = with the table)
      real(dp), allocatable :: uc(:)                 !! offsets: u = T q + uc
      real(dp), allocatable :: a(:, :)               !! state matrix (m x m)
      real(dp), allocatable :: b1(:), bag(:)         !! constant input, input of ag
      real(dp), allocatable :: minv_tt(:, :)         !! Mq^-1 T' (nq x n)
      real(dp) :: h = -1.0_dp                        !! step of the cached propagators
      real(dp), allocatable :: phi(:, :), g1(:, :), g2(:, :)           !! over h
      real(dp), allocatable :: gphi(:, :, :), gg1(:, :, :), gg2(:, :, :) !! at the Gauss points
      type(forcing_type) :: frc                      !! forcing of the particular solution
      real(dp), allocatable :: xp_s(:, :), xp_c(:, :) !! xp = sum_k xp_s(:,k) sin + xp_c(:,k) cos
      ! least-squares work, allocated with the pattern so that a step allocates nothing
      integer :: ns = 0                                       !! sticking active devices
      integer, allocatable :: ids(:)                          !! their indices
      real(dp), allocatable :: bm(:, :), rr(:, :), sv(:), lwk(:) !! least-squares work
   end type pattern_type

   !> State of the run.
   type :: coulomb_work
      integer :: n = 0, nd = 0
      real(dp), allocatable :: mass(:), k(:, :), c(:, :)
      real(dp), allocatable :: u(:), v(:), acc(:)         !! full state and acceleration
      real(dp), allocatable :: x(:)                       !! reduced state
      integer, allocatable :: phase(:)                    !! 0 stick, +-1 slip
      logical, allocatable :: fresh(:)                    !! slip started at s' = 0 this event
      logical, allocatable :: active(:)                   !! P mu > 0
      real(dp), allocatable :: force(:)                   !! device forces (stuck: required)
      real(dp), allocatable :: slip(:)                    !! P mu
      type(pattern_type) :: pat
      integer :: n_expm = 0, n_events = 0
      real(dp), allocatable :: g_end(:), g_try(:), s0(:)  !! event values, start positions (nd)
      real(dp), allocatable :: rn(:), vv(:)               !! work (n)
      ! work sized with each pattern (m = 2 nq), so that a step allocates nothing
      real(dp), allocatable :: ph(:, :), q1(:, :), q2(:, :)   !! propagators over the trial tau
      real(dp), allocatable :: pg(:, :), pq1(:, :), pq2(:, :) !! same at a Gauss point
      real(dp), allocatable :: y(:), y2(:), wk(:), xdot(:)    !! states and work (m)
   end type coulomb_work

contains

   !> Integrate a model whose devices all follow the exact Coulomb law.
   subroutine run_coulomb(model, exc, opts, res, error)
      type(model_type), intent(in) :: model         !! validated model (all devices coulomb)
      type(excitation_type), intent(in) :: exc      !! table motion
      type(integration_type), intent(in) :: opts    !! n1 and output_every are used
      type(result_type), intent(out) :: res         !! histories and summary
      type(error_type), allocatable, intent(out) :: error !! event chattering, singular phase
      type(coulomb_work) :: w
      type(forcing_type) :: frc
      real(dp) :: h, t, tn, tb, e_kin0, e_str0, w_fric
      integer :: k, nsteps, every, iout, c0, c1, crate, stat

      call system_clock(c0, crate)
      call setup(model, w, stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the matrices of n_dof = "//trim(fmt_int(model%n_dof))//" DOFs")
         return
      end if
      call structure_matrices(model, w%k, w%c, res%period_stuck, res%xi_stuck, error)
      if (allocated(error)) return
      call init_result(model, exc, opts, res, nsteps, every, error)
      if (allocated(error)) return
      h = exc%dt_record/opts%n1
      res%dt1 = h
      res%dt2 = 0.0_dp
      res%dt_min = 0.0_dp

      w%u = model%u0
      w%v = model%v0
      t = 0.0_dp
      w%phase = 0
      do k = 1, w%nd
         if (w%active(k) .and. abs(rel(model, k, w%v)) > 0.0_dp) w%phase(k) = int(sign(1.0_dp, rel(model, k, w%v)))
         if (.not. w%active(k)) w%phase(k) = 0
      end do
      call decide_phases(model, exc, t, w, res, .true., error)
      if (allocated(error)) return
      e_kin0 = 0.5_dp*sum(w%mass*w%v**2)
      call sym_matvec(w%k, w%u, w%rn, 1.0_dp, 0.0_dp)
      e_str0 = 0.5_dp*dot_product(w%u, w%rn)
      w_fric = 0.0_dp
      iout = 1
      call sample(model, exc, t, w, res, iout)

      do k = 1, nsteps
         tn = k*h
         ! step to tn, stopping at a change of the forcing law (end of the ramp)
         do
            tb = tn
            if (exc%kind == excitation_harmonic .and. exc%ramp_cycles > 0) then
               if (t < ramp_end(exc) .and. ramp_end(exc) < tn - 1.0e-12_dp*tn) tb = ramp_end(exc)
            end if
            call advance(model, exc, t, tb, h, w, res, w_fric, error)
            if (allocated(error)) return
            t = tb
            frc = forcing_at(exc, t)
            if (w%pat%frc%nf /= frc%nf) then
               call set_pattern(model, exc, t, w, error)   ! the ramp ended: steady forcing
               if (allocated(error)) return
            end if
            if (tb >= tn) exit
         end do
         t = tn
         res%steps_dt1 = res%steps_dt1 + 1
         call track(model, exc, t, w, res)
         if (mod(k, every) == 0 .or. k == nsteps) then
            if (.not. all(ieee_is_finite(w%u))) then
               call fatal_error(error, "exact Coulomb technique: the solution is not finite at t = "// &
                                trim(fmt_real(t))//" s")
               return
            end if
            iout = iout + 1
            call sample(model, exc, t, w, res, iout)
         end if
      end do
      res%e_kinetic = 0.5_dp*sum(w%mass*w%v**2) - e_kin0
      call sym_matvec(w%k, w%u, w%rn, 1.0_dp, 0.0_dp)
      res%e_strain = 0.5_dp*dot_product(w%u, w%rn) - e_str0
      res%e_friction = w_fric
      res%e_device = 0.0_dp
      res%e_residual = res%e_input - (res%e_kinetic + res%e_strain + res%e_viscous + res%e_friction)
      res%factorizations = w%n_expm
      res%events = w%n_events
      call system_clock(c1)
      res%run_time = real(c1 - c0, dp)/real(max(crate, 1), dp)
   end subroutine run_coulomb

   subroutine setup(model, w, stat)
      type(model_type), intent(in) :: model
      type(coulomb_work), intent(inout) :: w
      integer, intent(out) :: stat
      integer :: n, nd, d

      n = model%n_dof
      nd = model%n_devices
      w%n = n
      w%nd = nd
      w%mass = model%mass
      allocate (w%k(n, n), w%c(n, n), w%u(n), w%v(n), w%acc(n), stat=stat)
      if (stat /= 0) return
      allocate (w%phase(nd), w%fresh(nd), w%active(nd), w%force(nd), w%slip(nd))
      allocate (w%g_end(nd), w%g_try(nd), w%s0(nd), w%rn(n), w%vv(n))
      w%fresh = .false.
      w%force = 0.0_dp
      do d = 1, nd
         w%slip(d) = model%dev(d)%p*model%dev(d)%mu
         w%active(d) = w%slip(d) > 0.0_dp
      end do
   end subroutine setup

   !> End of the cosine ramp of harmonic table motion [s].
   pure real(dp) function ramp_end(exc)
      type(excitation_type), intent(in) :: exc
      ramp_end = exc%ramp_cycles/exc%frequency
   end function ramp_end

   !> Relative velocity (or displacement) of device d from a full vector.
   pure real(dp) function rel(model, d, y)
      type(model_type), intent(in) :: model
      integer, intent(in) :: d
      real(dp), intent(in) :: y(:)
      rel = y(model%dev(d)%node_i)
      if (model%dev(d)%node_j > 0) rel = rel - y(model%dev(d)%node_j)
   end function rel

   !> The forcing law on the segment containing t (harmonic motion only).
   pure function forcing_at(exc, t) result(frc)
      type(excitation_type), intent(in) :: exc
      real(dp), intent(in) :: t
      type(forcing_type) :: frc
      real(dp) :: om, nu

      frc%nf = 0
      if (exc%kind /= excitation_harmonic) return
      om = 2.0_dp*pi*exc%frequency
      if (exc%ramp_cycles > 0 .and. t < ramp_end(exc)*(1.0_dp - 1.0e-12_dp)) then
         ! a0 R sin(wt) with R = (1 - cos(nu t))/2, twice differentiated: three sines
         nu = pi/ramp_end(exc)
         frc%nf = 3
         frc%w = [om + nu, om - nu, om]
         frc%amp = exc%amplitude*[(om + nu)**2/4.0_dp, (om - nu)**2/4.0_dp, -om**2/2.0_dp]
      else
         frc%nf = 1
         frc%w(1) = om
         frc%amp(1) = -exc%amplitude*om**2
      end if
   end function forcing_at

   !> Build the reduced system of the current phases at time t and its propagators.
   subroutine set_pattern(model, exc, t, w, error)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      real(dp), intent(in) :: t
      type(coulomb_work), intent(inout) :: w
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: ipiv(:)
      real(dp), allocatable :: tq(:, :), mq(:), kq(:, :), cq(:, :), f1(:), fg(:), lhs(:, :), rhs(:, :)
      real(dp), allocatable :: mgrp(:), vq(:)
      integer :: n, i, d, nq, m, kf, info, j

      n = w%n
      if (allocated(w%pat%grp)) deallocate (w%pat%grp)
      allocate (w%pat%grp(n))
      call link_groups(model, w%active .and. w%phase == phase_stick, w%pat%grp, nq)
      m = 2*nq
      w%pat%nq = nq
      w%pat%m = m
      allocate (tq(n, nq))
      tq = 0.0_dp
      do i = 1, n
         if (w%pat%grp(i) > 0) tq(i, w%pat%grp(i)) = 1.0_dp
      end do
      ! reduced coordinates from the current state: q = mass-weighted mean of the group
      allocate (mgrp(nq), vq(nq))
      mgrp = matmul(transpose(tq), w%mass)
      w%x = [matmul(transpose(tq), w%mass*w%u)/mgrp, matmul(transpose(tq), w%mass*w%v)/mgrp]
      w%pat%uc = w%u - matmul(tq, w%x(1:nq))
      ! project the velocities on the constraints (they hold to round-off at an event)
      w%v = matmul(tq, w%x(nq + 1:m))
      mq = mgrp
      kq = matmul(transpose(tq), matmul(w%k, tq))
      cq = matmul(transpose(tq), matmul(w%c, tq))
      ! loads: constant part (offsets and sliding forces), and the table's inertia
      allocate (f1(n))
      f1 = -matmul(w%k, w%pat%uc)
      do d = 1, w%nd
         if (.not. w%active(d) .or. w%phase(d) == phase_stick) cycle
         call add_b(model, d, -w%phase(d)*w%slip(d), f1)
      end do
      fg = -w%mass
      w%pat%minv_tt = transpose(tq)
      do i = 1, nq
         w%pat%minv_tt(i, :) = w%pat%minv_tt(i, :)/mq(i)
      end do
      if (allocated(w%pat%a)) deallocate (w%pat%a)
      allocate (w%pat%a(m, m))
      w%pat%a = 0.0_dp
      do i = 1, nq
         w%pat%a(i, nq + i) = 1.0_dp
         w%pat%a(nq + i, 1:nq) = -kq(i, :)/mq(i)
         w%pat%a(nq + i, nq + 1:m) = -cq(i, :)/mq(i)
      end do
      w%pat%b1 = [spread(0.0_dp, 1, nq), matmul(w%pat%minv_tt, f1)]
      w%pat%bag = [spread(0.0_dp, 1, nq), matmul(w%pat%minv_tt, fg)]
      w%pat%h = -1.0_dp
      ! particular solution of the harmonic forcing: xp = P sin + Q cos per frequency,
      ! (A^2 + w^2 I) Q = -w amp bag, P = A Q / w
      w%pat%frc = forcing_at(exc, t)
      if (allocated(w%pat%xp_s)) deallocate (w%pat%xp_s, w%pat%xp_c)
      allocate (w%pat%xp_s(m, max_freq), w%pat%xp_c(m, max_freq))
      w%pat%xp_s = 0.0_dp
      w%pat%xp_c = 0.0_dp
      if (m > 0) then
         allocate (ipiv(m), lhs(m, m), rhs(m, 1))
         do kf = 1, w%pat%frc%nf
            lhs = matmul(w%pat%a, w%pat%a)
            do j = 1, m
               lhs(j, j) = lhs(j, j) + w%pat%frc%w(kf)**2
            end do
            rhs(:, 1) = -w%pat%frc%w(kf)*w%pat%frc%amp(kf)*w%pat%bag
            call lu_solve(lhs, rhs, ipiv, info)
            if (info /= 0) then
               call fatal_error(error, "exact Coulomb technique: the table frequency "// &
                                trim(fmt_real(w%pat%frc%w(kf)/(2.0_dp*pi)))//" Hz is a natural frequency of an "// &
                                "undamped phase of the structure (no steady state exists)")
               return
            end if
            w%pat%xp_c(:, kf) = rhs(:, 1)
            w%pat%xp_s(:, kf) = matmul(w%pat%a, rhs(:, 1))/w%pat%frc%w(kf)
         end do
      end if
      call pattern_work(w)
   end subroutine set_pattern

   !> Work arrays of the pattern: sized once here, reused by every step.
   subroutine pattern_work(w)
      type(coulomb_work), intent(inout) :: w
      integer :: m, n, ns, d

      m = w%pat%m
      n = w%n
      if (allocated(w%ph)) deallocate (w%ph, w%q1, w%q2, w%pg, w%pq1, w%pq2, w%y, w%y2, w%wk, w%xdot)
      allocate (w%ph(m, m), w%q1(m, m), w%q2(m, m), w%pg(m, m), w%pq1(m, m), w%pq2(m, m), &
                w%y(m), w%y2(m), w%wk(m), w%xdot(m))
      ns = count(w%active .and. w%phase == phase_stick)
      w%pat%ns = ns
      if (allocated(w%pat%ids)) deallocate (w%pat%ids, w%pat%bm, w%pat%rr, w%pat%sv, w%pat%lwk)
      allocate (w%pat%ids(ns), w%pat%bm(n, ns), w%pat%rr(max(n, ns), 1), w%pat%sv(max(1, min(n, ns))))
      ns = 0
      do d = 1, w%nd
         if (.not. w%active(d) .or. w%phase(d) /= phase_stick) cycle
         ns = ns + 1
         w%pat%ids(ns) = d
      end do
      allocate (w%pat%lwk(least_squares_work(n, ns)))
   end subroutine pattern_work

   pure subroutine add_b(model, d, alpha, y)
      type(model_type), intent(in) :: model
      integer, intent(in) :: d
      real(dp), intent(in) :: alpha
      real(dp), intent(inout) :: y(:)
      y(model%dev(d)%node_i) = y(model%dev(d)%node_i) + alpha
      if (model%dev(d)%node_j > 0) y(model%dev(d)%node_j) = y(model%dev(d)%node_j) - alpha
   end subroutine add_b

   !> Particular solution (harmonic forcing) at time t, into y.
   pure subroutine xp_into(pat, t, y)
      type(pattern_type), intent(in) :: pat
      real(dp), intent(in) :: t
      real(dp), intent(out) :: y(:)
      integer :: kf
      y = 0.0_dp
      do kf = 1, pat%frc%nf
         y = y + pat%xp_s(:, kf)*sin(pat%frc%w(kf)*t) + pat%xp_c(:, kf)*cos(pat%frc%w(kf)*t)
      end do
   end subroutine xp_into

   !> Reduced state at t + tau from the state x at t (wk: work of size m).
   subroutine propagate(exc, pat, t, tau, x, phi, g1, g2, y, wk)
      type(excitation_type), intent(in) :: exc
      type(pattern_type), intent(in) :: pat
      real(dp), intent(in) :: t, tau, x(:), phi(:, :), g1(:, :), g2(:, :)
      real(dp), intent(out) :: y(:)
      real(dp), intent(inout) :: wk(:)
      real(dp) :: ag0, ag1, xg, vg

      if (pat%m == 0) return
      ! y = phi (x - xp(t)) + xp(t + tau) + gam1 b1 [+ first-order hold of a record]
      call xp_into(pat, t, wk)
      wk = x - wk
      call gen_matvec(phi, wk, y, 1.0_dp, 0.0_dp)
      call xp_into(pat, t + tau, wk)
      y = y + wk
      call gen_matvec(g1, pat%b1, y, 1.0_dp, 1.0_dp)
      if (exc%kind == excitation_record) then
         ! steps never straddle a sample, so ag is linear over the step
         call table_motion(exc, t, xg, vg, ag0)
         call table_motion(exc, t + tau, xg, vg, ag1)
         call gen_matvec(g1, pat%bag, y, ag0, 1.0_dp)
         call gen_matvec(g2, pat%bag, y, (ag1 - ag0)/tau, 1.0_dp)
      end if
   end subroutine propagate

   !> Propagators over tau (cached for the full step h).
   subroutine propagators(pat, tau, h, phi, g1, g2, n_expm, error)
      type(pattern_type), intent(inout) :: pat
      real(dp), intent(in) :: tau, h
      real(dp), intent(out) :: phi(:, :), g1(:, :), g2(:, :)
      integer, intent(inout) :: n_expm
      type(error_type), allocatable, intent(out) :: error
      integer :: info, ig

      if (pat%m == 0) return
      if (tau == h) then
         if (pat%h /= h) then
            if (allocated(pat%phi)) deallocate (pat%phi, pat%g1, pat%g2, pat%gphi, pat%gg1, pat%gg2)
            allocate (pat%phi(pat%m, pat%m), pat%g1(pat%m, pat%m), pat%g2(pat%m, pat%m))
            allocate (pat%gphi(pat%m, pat%m, 3), pat%gg1(pat%m, pat%m, 3), pat%gg2(pat%m, pat%m, 3))
            call lti_propagators(pat%a, h, pat%phi, pat%g1, pat%g2, info)
            do ig = 1, 3
               call lti_propagators(pat%a, gl_x(ig)*h, pat%gphi(:, :, ig), pat%gg1(:, :, ig), &
                                    pat%gg2(:, :, ig), info)
            end do
            n_expm = n_expm + 4
            pat%h = h
         end if
         phi = pat%phi; g1 = pat%g1; g2 = pat%g2
         return
      end if
      call lti_propagators(pat%a, tau, phi, g1, g2, info)
      n_expm = n_expm + 1
      if (info /= 0) call fatal_error(error, "exact Coulomb technique: matrix exponential failed")
   end subroutine propagators

   !> Full displacement, velocity and acceleration from a reduced state at time t.
   subroutine expand(exc, t, x, w)
      type(excitation_type), intent(in) :: exc
      real(dp), intent(in) :: t, x(:)
      type(coulomb_work), intent(inout) :: w
      real(dp) :: xg, vg, ag
      integer :: i, g, nq

      associate (pat => w%pat, xdot => w%xdot)
      nq = pat%nq
      call table_motion(exc, t, xg, vg, ag)
      if (pat%m > 0) then
         xdot = pat%b1 + pat%bag*ag
         call gen_matvec(pat%a, x, xdot, 1.0_dp, 1.0_dp)
      end if
      do i = 1, w%n
         g = pat%grp(i)
         if (g == 0) then
            w%u(i) = pat%uc(i); w%v(i) = 0.0_dp; w%acc(i) = 0.0_dp
         else
            w%u(i) = x(g) + pat%uc(i); w%v(i) = x(nq + g); w%acc(i) = xdot(nq + g)
         end if
      end do
      end associate
   end subroutine expand

   !> Forces needed to keep the sticking devices stuck, at the expanded state (w%u, v, acc):
   !> B F = p - M a - C v - K u - sum_slip b sgn P mu, solved in the least-squares sense.
   subroutine stuck_forces(model, exc, t, w)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      real(dp), intent(in) :: t
      type(coulomb_work), intent(inout) :: w
      real(dp) :: xg, vg, ag
      integer :: d, k, info

      do d = 1, w%nd
         if (.not. w%active(d)) then
            w%force(d) = 0.0_dp
         else if (w%phase(d) /= phase_stick) then
            w%force(d) = w%phase(d)*w%slip(d)
         end if
      end do
      if (w%pat%ns == 0) return
      call table_motion(exc, t, xg, vg, ag)
      associate (r => w%pat%rr, bm => w%pat%bm)
         r(1:w%n, 1) = -w%mass*(ag + w%acc)
         call sym_matvec(w%c, w%v, r(1:w%n, 1), -1.0_dp, 1.0_dp)
         call sym_matvec(w%k, w%u, r(1:w%n, 1), -1.0_dp, 1.0_dp)
         do d = 1, w%nd
            if (w%active(d) .and. w%phase(d) /= phase_stick) call add_b(model, d, -w%force(d), r(1:w%n, 1))
         end do
         bm = 0.0_dp
         do k = 1, w%pat%ns
            call add_b(model, w%pat%ids(k), 1.0_dp, bm(:, k))
         end do
         call least_squares(bm, r, w%pat%sv, w%pat%lwk, info)
         do k = 1, w%pat%ns
            w%force(w%pat%ids(k)) = r(k, 1)
         end do
      end associate
   end subroutine stuck_forces

   !> Event functions at the expanded state: sliding devices sgn s' (> 0 while sliding on),
   !> sticking devices P mu - |F| (> 0 while the device holds).
   subroutine event_values(model, w, g)
      type(model_type), intent(in) :: model
      type(coulomb_work), intent(in) :: w
      real(dp), intent(out) :: g(:)
      integer :: d

      do d = 1, w%nd
         if (.not. w%active(d)) then
            g(d) = 1.0_dp
         else if (w%phase(d) == phase_stick) then
            g(d) = w%slip(d) - abs(w%force(d))
         else
            g(d) = w%phase(d)*rel(model, d, w%v)
         end if
      end do
   end subroutine event_values

   !> Advance from t to tb (<= one step h), locating and handling every event on the way.
   subroutine advance(model, exc, t, tb, h, w, res, w_fric, error)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      real(dp), intent(in) :: t, tb, h
      type(coulomb_work), intent(inout) :: w
      type(result_type), intent(inout) :: res
      real(dp), intent(inout) :: w_fric
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: tc, tau, a, b, fa, fb, c, fc, d_, e, tol, p, q, r_, s, xm, tau_ev
      integer :: m, d, it, stalls
      logical :: fired

      tc = t
      stalls = 0
      do
         if (tc >= tb) exit
         m = w%pat%m
         tau = tb - tc
         ! a full step (tb - tc differs from h by the rounding of k h): use the cached propagators
         if (abs(tau - h) <= 1.0e-9_dp*h) tau = h
         call propagators(w%pat, tau, h, w%ph, w%q1, w%q2, w%n_expm, error)
         if (allocated(error)) return
         call state_at(tau, w%g_end)
         ! which events fire in (tc, tc + tau]?
         fired = .false.
         tau_ev = tau
         do d = 1, w%nd
            if (w%g_end(d) > 0.0_dp) cycle
            if (w%phase(d) /= phase_stick .and. w%fresh(d) .and. w%g_end(d) == 0.0_dp) cycle
            fired = .true.
            ! Brent's method on g_d over [0, tau]: g_d(0) >= 0 (holding or sliding on)
            a = 0.0_dp; fa = 1.0_dp
            b = tau; fb = w%g_end(d)
            call brent_root(d, a, fa, b, fb, tau_ev)
            tau = min(tau, tau_ev)
         end do
         ! integrate energy over [tc, tc + tau] and move there
         call energy(tau)
         if (m > 0) then
            if (tau /= tb - tc .and. tau /= h) then
               call propagators(w%pat, tau, h, w%ph, w%q1, w%q2, w%n_expm, error)
               if (allocated(error)) return
            end if
            call propagate(exc, w%pat, tc, tau, w%x, w%ph, w%q1, w%q2, w%y, w%wk)
            w%x = w%y
         end if
         do d = 1, w%nd
            w%s0(d) = rel(model, d, w%u)
         end do
         call expand(exc, tc + tau, w%x, w)
         do d = 1, w%nd
            if (w%active(d) .and. w%phase(d) /= phase_stick) w_fric = w_fric + w%slip(d)*abs(rel(model, d, w%u) - w%s0(d))
         end do
         if (fired) then
            tc = tc + tau
         else
            tc = tb   ! the whole remaining interval (tau may be snapped to h)
         end if
         if (fired) then
            if (tau <= 1.0e-13_dp*max(1.0_dp, tc)) then
               stalls = stalls + 1
               if (stalls > 50) then
                  call fatal_error(error, "exact Coulomb technique: events accumulate at t = "// &
                                   trim(fmt_real(tc))//" s (stick-slip chattering)")
                  return
               end if
            else
               stalls = 0
            end if
            w%n_events = w%n_events + 1
            call decide_phases(model, exc, tc, w, res, .false., error)
            if (allocated(error)) return
         else
            w%fresh = .false.
            call stuck_forces(model, exc, tc, w)
         end if
      end do
   contains
      !> Event values at tc + tau (phi, g1, g2 must be the propagators over tau).
      subroutine state_at(tt, gv)
         real(dp), intent(in) :: tt
         real(dp), intent(out) :: gv(:)
         if (m > 0) then
            call propagate(exc, w%pat, tc, tt, w%x, w%ph, w%q1, w%q2, w%y, w%wk)
            call expand(exc, tc + tt, w%y, w)
         else
            call expand(exc, tc + tt, w%x, w)
         end if
         call stuck_forces(model, exc, tc + tt, w)
         call event_values(model, w, gv)
         ! back to the state at tc (expand overwrote u, v, acc)
         call expand(exc, tc, w%x, w)
      end subroutine state_at

      subroutine eval_g(dd, tt, gval)
         integer, intent(in) :: dd
         real(dp), intent(in) :: tt
         real(dp), intent(out) :: gval
         if (m > 0) then
            call propagators(w%pat, tt, h, w%ph, w%q1, w%q2, w%n_expm, error)
         end if
         call state_at(tt, w%g_try)
         gval = w%g_try(dd)
      end subroutine eval_g

      !> Brent's zero of g_dd on [a, b], fa > 0 >= fb; result: the smallest root found.
      subroutine brent_root(dd, a0, fa0, b0, fb0, root)
         integer, intent(in) :: dd
         real(dp), intent(in) :: a0, fa0, b0, fb0
         real(dp), intent(out) :: root
         a = a0; fa = fa0; b = b0; fb = fb0
         c = a; fc = fa; d_ = b - a; e = d_
         do it = 1, 200
            if (sign(1.0_dp, fb) == sign(1.0_dp, fc) .and. fb /= 0.0_dp) then
               c = a; fc = fa; d_ = b - a; e = d_
            end if
            if (abs(fc) < abs(fb) .and. fb /= 0.0_dp) then
               a = b; b = c; c = a
               fa = fb; fb = fc; fc = fa
            end if
            tol = 2.0_dp*epsilon(1.0_dp)*max(abs(tc + b), 1.0_dp) + tiny(1.0_dp)
            xm = 0.5_dp*(c - b)
            if (abs(xm) <= tol .or. fb == 0.0_dp) exit
            if (abs(e) >= tol .and. abs(fa) > abs(fb)) then
               s = fb/fa
               if (a == c) then
                  p = 2.0_dp*xm*s; q = 1.0_dp - s
               else
                  q = fa/fc; r_ = fb/fc
                  p = s*(2.0_dp*xm*q*(q - r_) - (b - a)*(r_ - 1.0_dp))
                  q = (q - 1.0_dp)*(r_ - 1.0_dp)*(s - 1.0_dp)
               end if
               if (p > 0.0_dp) q = -q
               p = abs(p)
               if (2.0_dp*p < min(3.0_dp*xm*q - abs(tol*q), abs(e*q))) then
                  e = d_; d_ = p/q
               else
                  d_ = xm; e = d_
               end if
            else
               d_ = xm; e = d_
            end if
            a = b; fa = fb
            if (abs(d_) > tol) then
               b = b + d_
            else
               b = b + sign(tol, xm)
            end if
            call eval_g(dd, b, fb)
         end do
         ! the root is where g first reaches <= 0: take the non-positive end of the bracket
         if (fb <= 0.0_dp) then
            root = b
         else
            root = c
         end if
         root = max(root, 0.0_dp)
      end subroutine brent_root

      !> Input and viscous work over [tc, tc + tt] by 3-point Gauss-Legendre on the exact state.
      subroutine energy(tt)
         real(dp), intent(in) :: tt
         real(dp) :: xg, vg, ag
         integer :: ig, i, info
         if (tt <= 0.0_dp) return
         do ig = 1, 3
            if (m > 0) then
               if (tt == h .and. w%pat%h == h) then
                  call propagate(exc, w%pat, tc, gl_x(ig)*tt, w%x, w%pat%gphi(:, :, ig), w%pat%gg1(:, :, ig), &
                                 w%pat%gg2(:, :, ig), w%y2, w%wk)
               else
                  call lti_propagators(w%pat%a, gl_x(ig)*tt, w%pg, w%pq1, w%pq2, info)
                  w%n_expm = w%n_expm + 1
                  call propagate(exc, w%pat, tc, gl_x(ig)*tt, w%x, w%pg, w%pq1, w%pq2, w%y2, w%wk)
               end if
               do i = 1, w%n
                  if (w%pat%grp(i) == 0) then
                     w%vv(i) = 0.0_dp
                  else
                     w%vv(i) = w%y2(w%pat%nq + w%pat%grp(i))
                  end if
               end do
            else
               w%vv = 0.0_dp
            end if
            call table_motion(exc, tc + gl_x(ig)*tt, xg, vg, ag)
            res%e_input = res%e_input - gl_w(ig)*tt*ag*sum(w%mass*w%vv)
            call sym_matvec(w%c, w%vv, w%rn, 1.0_dp, 0.0_dp)
            res%e_viscous = res%e_viscous + gl_w(ig)*tt*dot_product(w%vv, w%rn)
         end do
      end subroutine energy
   end subroutine advance

   !> At an event (or at t = 0): decide which devices stick. Candidates are the sticking
   !> devices and the sliding ones at s' = 0; the forces needed to keep all candidates stuck
   !> come from one least-squares solve; the candidate needing most above P mu slides in the
   !> direction of its force, and the solve is repeated.
   subroutine decide_phases(model, exc, t, w, res, initial, error)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      real(dp), intent(in) :: t
      type(coulomb_work), intent(inout) :: w
      type(result_type), intent(inout) :: res
      logical, intent(in) :: initial
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: old(:)
      logical, allocatable :: held(:)
      real(dp) :: ratio, worst
      integer :: d, dw, iter, pass
      real(dp) :: sd
      real(dp), parameter :: at_limit = 1.0_dp - 1.0e-9_dp  !! |F| / P mu that counts as the limit

      allocate (old(w%nd), held(w%nd))
      old = w%phase
      dw = 0
      held = .false.
      ! the state is expanded at t; candidates: stuck ones, and sliders at a velocity zero
      do d = 1, w%nd
         if (.not. w%active(d) .or. w%phase(d) == phase_stick) cycle
         sd = w%phase(d)*rel(model, d, w%v)
         if (sd <= 0.0_dp .and. .not. w%fresh(d)) w%phase(d) = phase_stick
      end do
      ! release, one at a time, the candidate that needs most above P mu (at the limit counts:
      ! its force got there increasing), in the direction of its force; keep the release only
      ! if the device then accelerates that way, else it holds
      do pass = 1, w%nd + 1
         dw = 0
         do iter = 1, 2*w%nd + 2
            call set_pattern(model, exc, t, w, error)
            if (allocated(error)) return
            call expand(exc, t, w%x, w)
            call stuck_forces(model, exc, t, w)
            if (dw > 0) then
               if (w%phase(dw)*rel(model, dw, w%acc) <= 0.0_dp) then
                  w%phase(dw) = phase_stick
                  w%fresh(dw) = .false.
                  held(dw) = .true.
                  dw = 0
                  cycle
               end if
            end if
            worst = at_limit
            dw = 0
            do d = 1, w%nd
               if (.not. w%active(d) .or. w%phase(d) /= phase_stick .or. held(d)) cycle
               ratio = abs(w%force(d))/w%slip(d)
               if (ratio >= worst) then
                  worst = ratio
                  dw = d
               end if
            end do
            if (dw == 0) exit
            w%phase(dw) = int(sign(1.0_dp, w%force(dw)))
            w%fresh(dw) = .true.
         end do
         ! a device released earlier may no longer accelerate in its direction once others
         ! were released: it holds, and the decision is made again
         dw = 0
         worst = 0.0_dp
         do d = 1, w%nd
            if (.not. w%fresh(d) .or. w%phase(d) == phase_stick) cycle
            ratio = w%phase(d)*rel(model, d, w%acc)
            if (ratio <= worst) then
               worst = ratio
               dw = d
            end if
         end do
         if (dw == 0) exit
         w%phase(dw) = phase_stick
         w%fresh(dw) = .false.
         held(dw) = .true.
      end do
      if (dw /= 0) then
         ! out of passes: leave the state consistent with the phases decided last
         call set_pattern(model, exc, t, w, error)
         if (allocated(error)) return
         call expand(exc, t, w%x, w)
         call stuck_forces(model, exc, t, w)
      end if
      do d = 1, w%nd
         if (w%phase(d) /= phase_stick) cycle
         w%fresh(d) = .false.
      end do
      if (initial) return
      do d = 1, w%nd
         call record_transition(res, d, old(d), w%phase(d))
      end do
   end subroutine decide_phases

   subroutine track(model, exc, t, w, res)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      real(dp), intent(in) :: t
      type(coulomb_work), intent(in) :: w
      type(result_type), intent(inout) :: res
      real(dp) :: xg, vg, ag, x
      integer :: i

      call table_motion(exc, t, xg, vg, ag)
      do i = 1, w%n
         if (abs(w%u(i)) > res%peak_u(i)) then
            res%peak_u(i) = abs(w%u(i)); res%peak_u_time(i) = t
         end if
         res%peak_v(i) = max(res%peak_v(i), abs(w%v(i)))
         x = abs(w%acc(i) + ag)
         if (x > res%peak_aabs(i)) then
            res%peak_aabs(i) = x; res%peak_aabs_time(i) = t
         end if
      end do
      do i = 1, w%nd
         res%peak_s(i) = max(res%peak_s(i), abs(rel(model, i, w%u)))
         res%peak_force(i) = max(res%peak_force(i), abs(w%force(i)))
      end do
   end subroutine track

   subroutine sample(model, exc, t, w, res, iout)
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      real(dp), intent(in) :: t
      type(coulomb_work), intent(in) :: w
      type(result_type), intent(inout) :: res
      integer, intent(in) :: iout
      real(dp) :: xg, vg, ag
      integer :: i, c

      if (iout > res%nout) return
      call table_motion(exc, t, xg, vg, ag)
      res%hist(1, iout) = t
      res%hist(2, iout) = ag
      c = 2
      do i = 1, w%n
         res%hist(c + 1:c + 3, iout) = [w%u(i), w%v(i), w%acc(i) + ag]
         c = c + 3
      end do
      do i = 1, w%nd
         res%hist(c + 1:c + 4, iout) = [rel(model, i, w%u), rel(model, i, w%v), w%force(i), &
                                        real(w%phase(i), dp)]
         c = c + 4
      end do
   end subroutine sample

end module fd_coulomb
