!> The reduced linear system of one phase pattern of the exact technique, and its exact
!> propagators. With the sticking devices rigid links, the nodes they join form groups
!> (none for a group holding the table); one reduced coordinate q per group, u = T q + u_c:
!>   x = (q, q'),  x' = A x + b1 + bag ag(t),  A = [[0, I], [-Mq^-1 Kq, -Mq^-1 Cq]]
!> (b1: the sliding forces and the springs' response to the offsets u_c; bag: the
!> table's inertia). Over a time tau it is integrated exactly,
!>   x(t + tau) = phi (x - xp(t)) + xp(t + tau) + gam1 (b1 + bag g0) + gam2 bag g1,
!> with the particular solution xp of a table acceleration that is a sum of sines, or the
!> first-order hold ag = g0 + g1 tau of one that is linear between samples.
module fd_phase_pattern
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_real, fmt_int
   use fd_model, only: model_type
   use fd_excitation, only: excitation_type, table_motion, sine_forcing, max_sines, table_sines, &
                            forcing_form, forcing_linear
   use fd_matrices, only: link_groups
   use fd_kinematics, only: add_device
   use fd_expm, only: lti_propagators
   use fd_linalg, only: gen_matvec, lu_solve
   use fd_device_state, only: phase_stick
   implicit none
   private

   public :: pattern_type, build_pattern, forcing_changed, pattern_propagators, pattern_exp
   public :: propagate, expand_pattern, quad_x, quad_w

   real(dp), parameter :: pi = acos(-1.0_dp)
   !> 3-point Gauss-Legendre rule on [0, 1], nodes and weights: the energy quadrature of the
   !> exact technique, whose propagators the pattern keeps for the full step.
   real(dp), parameter :: quad_x(3) = [0.5_dp - sqrt(0.15_dp), 0.5_dp, 0.5_dp + sqrt(0.15_dp)]
   real(dp), parameter :: quad_w(3) = [5.0_dp/18.0_dp, 8.0_dp/18.0_dp, 5.0_dp/18.0_dp]

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
      real(dp), allocatable :: gphi(:, :, :), gg1(:, :, :), gg2(:, :, :) !! over h quad_x
      type(sine_forcing) :: frc                      !! forcing of the particular solution
      logical :: linear = .false.                    !! ag linear between samples (first-order hold)
      real(dp), allocatable :: xp_s(:, :), xp_c(:, :) !! xp = sum_k xp_s(:,k) sin + xp_c(:,k) cos
   end type pattern_type

contains

   !> Build the reduced system of the phases at time t, its reduced state x from the full
   !> state (q: the mass-weighted mean of each group), and project the velocities v on the
   !> constraints (they hold to round-off at an event).
   subroutine build_pattern(model, mass, k, c, active, phase, slip, exc, t, u, v, x, pat, error)
      type(model_type), intent(in) :: model         !! the model (device nodes)
      real(dp), intent(in) :: mass(:)               !! lumped masses
      real(dp), intent(in) :: k(:, :)               !! springs' stiffness
      real(dp), intent(in) :: c(:, :)               !! viscous damping
      logical, intent(in) :: active(:)              !! devices with P mu > 0
      integer, intent(in) :: phase(:)               !! device phases (0 stick, +-1 slip)
      real(dp), intent(in) :: slip(:)               !! P mu of each device
      type(excitation_type), intent(in) :: exc      !! the table motion
      real(dp), intent(in) :: t                     !! time [s]
      real(dp), intent(in) :: u(:)                  !! displacements
      real(dp), intent(inout) :: v(:)               !! velocities, projected on return
      real(dp), allocatable, intent(inout) :: x(:)  !! reduced state (2 nq)
      type(pattern_type), intent(inout) :: pat      !! the pattern
      type(error_type), allocatable, intent(out) :: error !! no steady state of the forcing
      integer, allocatable :: ipiv(:)
      real(dp), allocatable :: tq(:, :), mq(:), kq(:, :), cq(:, :), f1(:), fg(:), lhs(:, :), rhs(:, :)
      real(dp), allocatable :: mgrp(:), vq(:)
      integer :: n, i, d, nq, m, kf, info, j

      n = size(mass)
      if (allocated(pat%grp)) deallocate (pat%grp)
      allocate (pat%grp(n))
      call link_groups(model, active .and. phase == phase_stick, pat%grp, nq)
      m = 2*nq
      pat%nq = nq
      pat%m = m
      allocate (tq(n, nq))
      tq = 0.0_dp
      do i = 1, n
         if (pat%grp(i) > 0) tq(i, pat%grp(i)) = 1.0_dp
      end do
      ! reduced coordinates from the current state: q = mass-weighted mean of the group
      allocate (mgrp(nq), vq(nq))
      mgrp = matmul(transpose(tq), mass)
      x = [matmul(transpose(tq), mass*u)/mgrp, matmul(transpose(tq), mass*v)/mgrp]
      pat%uc = u - matmul(tq, x(1:nq))
      ! project the velocities on the constraints (they hold to round-off at an event)
      v = matmul(tq, x(nq + 1:m))
      mq = mgrp
      kq = matmul(transpose(tq), matmul(k, tq))
      cq = matmul(transpose(tq), matmul(c, tq))
      ! loads: constant part (offsets and sliding forces), and the table's inertia
      allocate (f1(n))
      f1 = -matmul(k, pat%uc)
      do d = 1, size(phase)
         if (.not. active(d) .or. phase(d) == phase_stick) cycle
         call add_device(model, d, -phase(d)*slip(d), f1)
      end do
      fg = -mass
      pat%minv_tt = transpose(tq)
      do i = 1, nq
         pat%minv_tt(i, :) = pat%minv_tt(i, :)/mq(i)
      end do
      if (allocated(pat%a)) deallocate (pat%a)
      allocate (pat%a(m, m))
      pat%a = 0.0_dp
      do i = 1, nq
         pat%a(i, nq + i) = 1.0_dp
         pat%a(nq + i, 1:nq) = -kq(i, :)/mq(i)
         pat%a(nq + i, nq + 1:m) = -cq(i, :)/mq(i)
      end do
      pat%b1 = [spread(0.0_dp, 1, nq), matmul(pat%minv_tt, f1)]
      pat%bag = [spread(0.0_dp, 1, nq), matmul(pat%minv_tt, fg)]
      pat%h = -1.0_dp
      ! particular solution of the harmonic forcing: xp = P sin + Q cos per frequency,
      ! (A^2 + w^2 I) Q = -w amp bag, P = A Q / w
      call table_sines(exc, t, pat%frc)
      pat%linear = forcing_form(exc) == forcing_linear
      if (allocated(pat%xp_s)) deallocate (pat%xp_s, pat%xp_c)
      allocate (pat%xp_s(m, max_sines), pat%xp_c(m, max_sines))
      pat%xp_s = 0.0_dp
      pat%xp_c = 0.0_dp
      if (m > 0) then
         allocate (ipiv(m), lhs(m, m), rhs(m, 1))
         do kf = 1, pat%frc%nf
            lhs = matmul(pat%a, pat%a)
            do j = 1, m
               lhs(j, j) = lhs(j, j) + pat%frc%w(kf)**2
            end do
            rhs(:, 1) = -pat%frc%w(kf)*pat%frc%amp(kf)*pat%bag
            call lu_solve(lhs, rhs, ipiv, info)
            if (info /= 0) then
               call fatal_error(error, "event-driven technique: the table frequency "// &
                                trim(fmt_real(pat%frc%w(kf)/(2.0_dp*pi)))//" Hz is a natural frequency of an "// &
                                "undamped phase of the structure (no steady state exists)")
               return
            end if
            pat%xp_c(:, kf) = rhs(:, 1)
            pat%xp_s(:, kf) = matmul(pat%a, rhs(:, 1))/pat%frc%w(kf)
         end do
      end if
   end subroutine build_pattern

   !> Whether the form of the forcing at t (the number of sines) differs from the one the
   !> pattern was built with: the harmonic ramp has ended, and the pattern must be rebuilt.
   pure logical function forcing_changed(pat, exc, t)
      type(pattern_type), intent(in) :: pat         !! the pattern
      type(excitation_type), intent(in) :: exc      !! the table motion
      real(dp), intent(in) :: t                     !! time [s]
      type(sine_forcing) :: frc

      call table_sines(exc, t, frc)
      forcing_changed = pat%frc%nf /= frc%nf
   end function forcing_changed

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

   !> Reduced state y at t + tau from the state x at t, with the propagators over tau.
   subroutine propagate(exc, pat, t, tau, x, phi, g1, g2, y, wk)
      type(excitation_type), intent(in) :: exc      !! the table motion
      type(pattern_type), intent(in) :: pat         !! the pattern
      real(dp), intent(in) :: t                     !! start time [s]
      real(dp), intent(in) :: tau                   !! time step [s]
      real(dp), intent(in) :: x(:)                  !! reduced state at t
      real(dp), intent(in) :: phi(:, :)             !! exp(A tau)
      real(dp), intent(in) :: g1(:, :)              !! response to a constant input over tau
      real(dp), intent(in) :: g2(:, :)              !! response to a ramp input over tau
      real(dp), intent(out) :: y(:)                 !! reduced state at t + tau
      real(dp), intent(inout) :: wk(:)              !! work (m)
      real(dp) :: ag0, ag1, xg, vg

      if (pat%m == 0) return
      ! y = phi (x - xp(t)) + xp(t + tau) + gam1 b1 [+ first-order hold of a record]
      call xp_into(pat, t, wk)
      wk = x - wk
      call gen_matvec(phi, wk, y, 1.0_dp, 0.0_dp)
      call xp_into(pat, t + tau, wk)
      y = y + wk
      call gen_matvec(g1, pat%b1, y, 1.0_dp, 1.0_dp)
      if (pat%linear) then
         ! steps never straddle a sample, so ag is linear over the step
         call table_motion(exc, t, xg, vg, ag0)
         call table_motion(exc, t + tau, xg, vg, ag1)
         call gen_matvec(g1, pat%bag, y, ag0, 1.0_dp)
         call gen_matvec(g2, pat%bag, y, (ag1 - ag0)/tau, 1.0_dp)
      end if
   end subroutine propagate

   !> Propagators over tau, computed (one matrix exponential, counted in n_expm).
   subroutine pattern_exp(pat, tau, phi, g1, g2, n_expm, error)
      type(pattern_type), intent(in) :: pat         !! the pattern
      real(dp), intent(in) :: tau                   !! time step [s]
      real(dp), intent(out) :: phi(:, :)            !! exp(A tau)
      real(dp), intent(out) :: g1(:, :)             !! response to a constant input
      real(dp), intent(out) :: g2(:, :)             !! response to a ramp input
      integer, intent(inout) :: n_expm              !! matrix exponentials computed
      type(error_type), allocatable, intent(out) :: error !! failure of the exponential
      integer :: info

      if (pat%m == 0) return
      call lti_propagators(pat%a, tau, phi, g1, g2, info)
      n_expm = n_expm + 1
      if (info /= 0) call expm_failed(tau, info, error)
   end subroutine pattern_exp

   !> Propagators over tau: for the full step h those kept in the pattern (computed, with
   !> those at the quadrature nodes, the first time), else computed.
   subroutine pattern_propagators(pat, tau, h, phi, g1, g2, n_expm, error)
      type(pattern_type), intent(inout) :: pat      !! the pattern (its cache)
      real(dp), intent(in) :: tau                   !! time step [s]
      real(dp), intent(in) :: h                     !! the full step [s]
      real(dp), intent(out) :: phi(:, :)            !! exp(A tau)
      real(dp), intent(out) :: g1(:, :)             !! response to a constant input
      real(dp), intent(out) :: g2(:, :)             !! response to a ramp input
      integer, intent(inout) :: n_expm              !! matrix exponentials computed
      type(error_type), allocatable, intent(out) :: error !! failure of an exponential
      integer :: info, ig

      if (pat%m == 0) return
      if (tau == h) then
         if (pat%h /= h) then
            if (allocated(pat%phi)) deallocate (pat%phi, pat%g1, pat%g2, pat%gphi, pat%gg1, pat%gg2)
            allocate (pat%phi(pat%m, pat%m), pat%g1(pat%m, pat%m), pat%g2(pat%m, pat%m))
            allocate (pat%gphi(pat%m, pat%m, 3), pat%gg1(pat%m, pat%m, 3), pat%gg2(pat%m, pat%m, 3))
            call lti_propagators(pat%a, h, pat%phi, pat%g1, pat%g2, info)
            n_expm = n_expm + 1
            if (info /= 0) then
               call expm_failed(h, info, error)
               return
            end if
            do ig = 1, 3
               call lti_propagators(pat%a, quad_x(ig)*h, pat%gphi(:, :, ig), pat%gg1(:, :, ig), &
                                    pat%gg2(:, :, ig), info)
               n_expm = n_expm + 1
               if (info /= 0) then
                  call expm_failed(quad_x(ig)*h, info, error)
                  return
               end if
            end do
            pat%h = h
         end if
         phi = pat%phi; g1 = pat%g1; g2 = pat%g2
         return
      end if
      call pattern_exp(pat, tau, phi, g1, g2, n_expm, error)
   end subroutine pattern_propagators

   subroutine expm_failed(tau, info, error)
      real(dp), intent(in) :: tau
      integer, intent(in) :: info
      type(error_type), allocatable, intent(out) :: error

      call fatal_error(error, "event-driven technique: the matrix exponential of a phase over "// &
                       trim(fmt_real(tau))//" s failed (LAPACK info = "//trim(fmt_int(info))//")")
   end subroutine expm_failed

   !> Full displacement, velocity and relative acceleration at time t from a reduced state.
   subroutine expand_pattern(exc, pat, t, x, u, v, acc, xdot)
      type(excitation_type), intent(in) :: exc      !! the table motion
      type(pattern_type), intent(in) :: pat         !! the pattern
      real(dp), intent(in) :: t                     !! time [s]
      real(dp), intent(in) :: x(:)                  !! reduced state at t
      real(dp), intent(out) :: u(:)                 !! displacements
      real(dp), intent(out) :: v(:)                 !! velocities
      real(dp), intent(out) :: acc(:)               !! relative accelerations
      real(dp), intent(inout) :: xdot(:)            !! work (m): x' at t
      real(dp) :: xg, vg, ag
      integer :: i, g, nq

      nq = pat%nq
      call table_motion(exc, t, xg, vg, ag)
      if (pat%m > 0) then
         xdot = pat%b1 + pat%bag*ag
         call gen_matvec(pat%a, x, xdot, 1.0_dp, 1.0_dp)
      end if
      do i = 1, size(u)
         g = pat%grp(i)
         if (g == 0) then
            u(i) = pat%uc(i); v(i) = 0.0_dp; acc(i) = 0.0_dp
         else
            u(i) = x(g) + pat%uc(i); v(i) = x(nq + g); acc(i) = xdot(nq + g)
         end if
      end do
   end subroutine expand_pattern

end module fd_phase_pattern
