!> Unit tests of the reduced LTI system of a phase pattern and its exact propagators
!> (fd_phase_pattern) against closed forms: a free damped oscillator, a rigid body under a
!> constant (sliding friction) force, an undamped oscillator under harmonic table motion
!> (the particular solution), a free mass under a piecewise-linear record (the first-order
!> hold), and a mass stuck to the table (no reduced DOF).
module test_fd_phase_pattern
   use testdrive, only: new_unittest, unittest_type, error_type, check, test_failed
   use fd_kinds, only: dp
   use fd_error, only: fd_error_type => error_type
   use fd_model, only: model_type, device_type, law_coulomb
   use fd_excitation, only: excitation_type, excitation_none, excitation_harmonic, excitation_record
   use fd_phase_pattern, only: pattern_type, build_pattern, pattern_exp, pattern_propagators, propagate, &
                               expand_pattern
   implicit none
   private

   public :: collect_phase_pattern

   real(dp), parameter :: pi = acos(-1.0_dp)

contains

   subroutine collect_phase_pattern(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("free damped oscillator", test_damped_oscillator), &
                  new_unittest("kept propagators of the full step", test_cached_step), &
                  new_unittest("rigid body under a constant force", test_sliding_block), &
                  new_unittest("harmonic table motion (particular solution)", test_harmonic), &
                  new_unittest("record (first-order hold)", test_record), &
                  new_unittest("mass stuck to the table", test_stuck_to_table) &
                  ]
   end subroutine collect_phase_pattern

   !> One mass, optionally with one device to the table.
   subroutine one_mass(m, with_device, model)
      real(dp), intent(in) :: m
      logical, intent(in) :: with_device
      type(model_type), intent(out) :: model

      model%n_dof = 1
      model%mass = [m]
      model%u0 = [0.0_dp]
      model%v0 = [0.0_dp]
      if (with_device) then
         model%n_devices = 1
         model%dev = [device_type(node_i=1, node_j=0, law=law_coulomb, p=10.0_dp, mu=0.5_dp)]
      else
         model%n_devices = 0
         allocate (model%dev(0))
      end if
   end subroutine one_mass

   !> Build the pattern of one mass (stiffness k, damping c) at t from (u0, v0).
   subroutine build_one(model, k, c, phase, exc, t, u0, v0, x, pat, error)
      type(model_type), intent(in) :: model
      real(dp), intent(in) :: k, c
      integer, intent(in) :: phase(:)
      type(excitation_type), intent(in) :: exc
      real(dp), intent(in) :: t, u0, v0
      real(dp), allocatable, intent(inout) :: x(:)
      type(pattern_type), intent(inout) :: pat
      type(error_type), allocatable, intent(out) :: error
      type(fd_error_type), allocatable :: err
      real(dp) :: kk(1, 1), cc(1, 1), v(1)
      logical :: active(size(phase))
      real(dp) :: slip(size(phase))

      kk = k; cc = c; v = v0
      active = .true.
      slip = 5.0_dp
      call build_pattern(model, model%mass, kk, cc, active, phase, slip, exc, t, [u0], v, x, pat, err)
      if (allocated(err)) call test_failed(error, err%message)
   end subroutine build_one

   !> Propagate the pattern's state x from t over tau into y (one matrix exponential).
   subroutine step(pat, exc, t, tau, x, y, error)
      type(pattern_type), intent(in) :: pat
      type(excitation_type), intent(in) :: exc
      real(dp), intent(in) :: t, tau, x(:)
      real(dp), intent(out) :: y(:)
      type(error_type), allocatable, intent(out) :: error
      type(fd_error_type), allocatable :: err
      real(dp) :: phi(pat%m, pat%m), g1(pat%m, pat%m), g2(pat%m, pat%m), wk(pat%m)
      integer :: n_expm

      n_expm = 0
      call pattern_exp(pat, tau, phi, g1, g2, n_expm, err)
      if (allocated(err)) then
         call test_failed(error, err%message); return
      end if
      call check(error, n_expm, 1)
      if (allocated(error)) return
      call propagate(exc, pat, t, tau, x, phi, g1, g2, y, wk)
   end subroutine step

   !> m u'' + c u' + k u = 0: u = e^(-z w t) (u0 cos wd t + (v0 + z w u0)/wd sin wd t),
   !> over 1.2 periods (measured error 1.1e-14 of the amplitude: the exponential of A tau,
   !> |A tau| = 150, is scaled by 2^5 and squared back).
   subroutine test_damped_oscillator(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(pattern_type) :: pat
      real(dp), allocatable :: x(:)
      real(dp) :: y(2), m, k, c, w, z, wd, u0, v0, tau, e, u, v, amp
      integer :: no_phase(0)

      m = 2.0_dp; k = 800.0_dp; z = 0.05_dp
      w = sqrt(k/m); c = 2.0_dp*z*w*m; wd = w*sqrt(1.0_dp - z*z)
      u0 = 0.01_dp; v0 = -0.3_dp; tau = 0.37_dp
      call one_mass(m, .false., model)
      exc%kind = excitation_none
      call build_one(model, k, c, no_phase, exc, 0.0_dp, u0, v0, x, pat, error)
      if (allocated(error)) return
      call check(error, pat%nq, 1)
      if (allocated(error)) return
      call step(pat, exc, 0.0_dp, tau, x, y, error)
      if (allocated(error)) return
      e = exp(-z*w*tau)
      u = e*(u0*cos(wd*tau) + (v0 + z*w*u0)/wd*sin(wd*tau))
      v = e*(v0*cos(wd*tau) - (w*w*u0 + z*w*v0)/wd*sin(wd*tau))
      amp = sqrt(u0**2 + ((v0 + z*w*u0)/wd)**2)
      call check(error, y(1), u, thr=1.0e-13_dp*amp)
      if (allocated(error)) return
      call check(error, y(2), v, thr=1.0e-13_dp*amp*w)
   end subroutine test_damped_oscillator

   !> The propagators kept for the full step h are those of one exponential over h, made
   !> once (with the three quadrature nodes: 4 exponentials) and then reused.
   subroutine test_cached_step(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(pattern_type) :: pat
      type(fd_error_type), allocatable :: err
      real(dp), allocatable :: x(:)
      real(dp) :: phi(2, 2), g1(2, 2), g2(2, 2), p2(2, 2), q1(2, 2), q2(2, 2), h
      integer :: n_expm, no_phase(0)

      call one_mass(2.0_dp, .false., model)
      exc%kind = excitation_none
      call build_one(model, 800.0_dp, 4.0_dp, no_phase, exc, 0.0_dp, 0.01_dp, 0.0_dp, x, pat, error)
      if (allocated(error)) return
      h = 2.5e-4_dp
      n_expm = 0
      call pattern_propagators(pat, h, h, phi, g1, g2, n_expm, err)
      call check(error, .not. allocated(err) .and. n_expm == 4, "first full step: 4 exponentials")
      if (allocated(error)) return
      call pattern_propagators(pat, h, h, p2, q1, q2, n_expm, err)
      call check(error, .not. allocated(err) .and. n_expm == 4, "second full step: none")
      if (allocated(error)) return
      call check(error, all(p2 == phi) .and. all(q1 == g1) .and. all(q2 == g2), "kept propagators differ")
      if (allocated(error)) return
      call pattern_exp(pat, h, p2, q1, q2, n_expm, err)
      call check(error, all(p2 == phi) .and. all(q1 == g1) .and. all(q2 == g2), &
                 "kept propagators differ from one exponential over h")
   end subroutine test_cached_step

   !> A block sliding (phase +1) on the table: u'' = -P mu / m, u = u0 + v0 t - P mu t^2 / (2 m)
   !> (measured error 1 ulp).
   subroutine test_sliding_block(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(pattern_type) :: pat
      real(dp), allocatable :: x(:)
      real(dp) :: y(2), m, a, u0, v0, tau, u(1), v(1), acc(1), xdot(2)

      m = 2.0_dp; u0 = 0.003_dp; v0 = 0.8_dp; tau = 0.21_dp
      a = 5.0_dp/m                          ! slip force P mu = 5 N (build_one)
      call one_mass(m, .true., model)
      exc%kind = excitation_none
      call build_one(model, 0.0_dp, 0.0_dp, [1], exc, 0.0_dp, u0, v0, x, pat, error)
      if (allocated(error)) return
      call check(error, pat%nq, 1)
      if (allocated(error)) return
      call step(pat, exc, 0.0_dp, tau, x, y, error)
      if (allocated(error)) return
      call check(error, y(1), u0 + v0*tau - 0.5_dp*a*tau**2, thr=4.0_dp*epsilon(1.0_dp)*0.2_dp)
      if (allocated(error)) return
      call check(error, y(2), v0 - a*tau, thr=4.0_dp*epsilon(1.0_dp))
      if (allocated(error)) return
      ! the full state: u, v and the constant deceleration
      call expand_pattern(exc, pat, tau, y, u, v, acc, xdot)
      call check(error, acc(1), -a, thr=4.0_dp*epsilon(1.0_dp)*a)
      if (allocated(error)) return
      call check(error, u(1) == y(1) .and. v(1) == y(2), "expand: u, v differ from the reduced state")
   end subroutine test_sliding_block

   !> u'' + w0^2 u = a0 w^2 sin(w t) from rest (table displacement a0 sin(w t)):
   !> u = a0 w^2 / (w0^2 - w^2) (sin w t - (w / w0) sin w0 t); from t = 0, and from the
   !> closed-form state at t1 = 0.35 s, where the particular solution is not at its start.
   !> (Measured error 3e-15 of the amplitude.)
   subroutine test_harmonic(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(pattern_type) :: pat
      real(dp), allocatable :: x(:)
      real(dp) :: y(2), w0, w, a0, amp, t1, tau
      integer :: no_phase(0)

      w0 = 10.0_dp
      exc%kind = excitation_harmonic
      exc%amplitude = 0.01_dp
      exc%frequency = 1.0_dp
      exc%ramp_cycles = 0
      a0 = exc%amplitude; w = 2.0_dp*pi*exc%frequency
      amp = a0*w*w/(w0*w0 - w*w)*(1.0_dp + w/w0)
      call one_mass(1.0_dp, .false., model)
      call build_one(model, w0*w0, 0.0_dp, no_phase, exc, 0.0_dp, 0.0_dp, 0.0_dp, x, pat, error)
      if (allocated(error)) return
      tau = 0.9_dp
      call step(pat, exc, 0.0_dp, tau, x, y, error)
      if (allocated(error)) return
      call check(error, y(1), u_exact(tau), thr=1.0e-14_dp*amp)
      if (allocated(error)) return
      call check(error, y(2), v_exact(tau), thr=1.0e-14_dp*amp*w0)
      if (allocated(error)) return
      t1 = 0.35_dp
      x = [u_exact(t1), v_exact(t1)]
      call step(pat, exc, t1, tau, x, y, error)
      if (allocated(error)) return
      call check(error, y(1), u_exact(t1 + tau), thr=1.0e-14_dp*amp)
      if (allocated(error)) return
      call check(error, y(2), v_exact(t1 + tau), thr=1.0e-14_dp*amp*w0)
   contains
      real(dp) function u_exact(t)
         real(dp), intent(in) :: t
         u_exact = a0*w*w/(w0*w0 - w*w)*(sin(w*t) - w/w0*sin(w0*t))
      end function u_exact
      real(dp) function v_exact(t)
         real(dp), intent(in) :: t
         v_exact = a0*w*w/(w0*w0 - w*w)*(w*cos(w*t) - w*cos(w0*t))
      end function v_exact
   end subroutine test_harmonic

   !> A free mass under a record, linear between samples: u'' = -(g0 + g1 t), so
   !> u = u0 + v0 t - g0 t^2 / 2 - g1 t^3 / 6, over the whole interval and inside it
   !> (measured error 2 ulps).
   subroutine test_record(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(pattern_type) :: pat
      real(dp), allocatable :: x(:)
      real(dp) :: y(2), g0, g1, u0, v0, tau
      integer :: i, no_phase(0)
      real(dp), parameter :: taus(2) = [0.1_dp, 0.06_dp]

      exc%kind = excitation_record
      exc%dt_record = 0.1_dp
      exc%acc = [1.5_dp, -0.5_dp]
      g0 = 1.5_dp; g1 = -20.0_dp
      u0 = 0.002_dp; v0 = 0.05_dp
      call one_mass(3.0_dp, .false., model)
      call build_one(model, 0.0_dp, 0.0_dp, no_phase, exc, 0.0_dp, u0, v0, x, pat, error)
      if (allocated(error)) return
      do i = 1, 2
         tau = taus(i)
         call step(pat, exc, 0.0_dp, tau, x, y, error)
         if (allocated(error)) return
         call check(error, y(1), u0 + v0*tau - g0*tau**2/2.0_dp - g1*tau**3/6.0_dp, thr=1.0e-17_dp)
         if (allocated(error)) return
         call check(error, y(2), v0 - g0*tau - g1*tau**2/2.0_dp, thr=1.0e-15_dp)
         if (allocated(error)) return
      end do
   end subroutine test_record

   !> A sticking device to the table links the mass to it: no reduced DOF, and the expanded
   !> state keeps its displacement with no velocity or acceleration (the velocity projected
   !> on the constraint).
   subroutine test_stuck_to_table(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(pattern_type) :: pat
      real(dp), allocatable :: x(:)
      real(dp) :: u(1), v(1), acc(1), xdot(0)

      exc%kind = excitation_harmonic
      exc%amplitude = 0.01_dp
      exc%frequency = 2.0_dp
      call one_mass(2.0_dp, .true., model)
      call build_one(model, 100.0_dp, 1.0_dp, [0], exc, 0.3_dp, 0.004_dp, 1.0e-12_dp, x, pat, error)
      if (allocated(error)) return
      call check(error, pat%nq == 0 .and. pat%m == 0 .and. size(x) == 0, "stuck to the table: no reduced DOF")
      if (allocated(error)) return
      call expand_pattern(exc, pat, 0.5_dp, x, u, v, acc, xdot)
      call check(error, u(1) == 0.004_dp .and. v(1) == 0.0_dp .and. acc(1) == 0.0_dp, &
                 "stuck to the table: the mass moved")
   end subroutine test_stuck_to_table

end module test_fd_phase_pattern
