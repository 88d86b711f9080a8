!> Unit tests of Newmark's own frequency and damping of an oscillator (fd_stick_ringing's
!> newmark_frequency): the closed forms of the average and linear acceleration rules, the
!> small-step damping of gamma > 1/2, and the frequency of the recursion itself, run step
!> by step (an independent computation); a bearing's observed normal force beyond the deck's
!> moves its sticking spring, its frequency error and its capacities (ringing_normal_force).
module test_fd_stick_ringing
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_stick_ringing, only: newmark_frequency, ringing_type, ringing_normal_force
   use fd_model, only: model_type, device_type
   use fd_names, only: law_hysteretic
   use fd_result, only: result_type
   implicit none
   private

   public :: collect_stick_ringing

   real(dp), parameter :: pi = acos(-1.0_dp)

contains

   subroutine collect_stick_ringing(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("average acceleration: 2 atan(w / 2), no damping", test_average), &
                  new_unittest("linear acceleration: its cosine, unstable beyond sqrt(12)", test_linear), &
                  new_unittest("gamma > 1/2: damping (gamma - 1/2) w / 2 at small steps", test_damped), &
                  new_unittest("the frequency of the recursion run step by step", test_recursion), &
                  new_unittest("a bearing's observed N: spring and error at the largest", test_observed_force) &
                  ]
   end subroutine collect_stick_ringing

   subroutine test_average(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: w, wt, z
      logical :: osc
      integer :: k

      do k = 1, 60
         w = 0.05_dp*k
         call newmark_frequency(w, 0.25_dp, 0.5_dp, wt, z, osc)
         call check(error, osc, "the average acceleration rule always oscillates")
         if (allocated(error)) return
         call check(error, abs(wt - 2*atan(w/2)) <= 4*epsilon(1.0_dp)*wt, "omega~ dt = 2 atan(omega dt / 2)")
         if (allocated(error)) return
         call check(error, abs(z) <= 4*epsilon(1.0_dp), "no numerical damping")
         if (allocated(error)) return
      end do
      ! the error the module reports, 1 - wt / w: 2.76 % at w = 0.59 (docs/theory.md)
      call newmark_frequency(0.59_dp, 0.25_dp, 0.5_dp, wt, z, osc)
      call check(error, abs(1 - wt/0.59_dp - 0.0275819_dp) < 1e-7_dp, "2.76 % at omega dt = 0.59")
   end subroutine test_average

   subroutine test_linear(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: w, wt, z
      logical :: osc
      integer :: k

      do k = 1, 34
         w = 0.1_dp*k                       ! up to 3.4 < sqrt(12) = 3.46
         call newmark_frequency(w, 1.0_dp/6, 0.5_dp, wt, z, osc)
         call check(error, osc, "oscillates below sqrt(12)")
         if (allocated(error)) return
         call check(error, abs(cos(wt) - (1 - w*w/(2*(1 + w*w/6)))) <= 8*epsilon(1.0_dp), &
                    "cos(omega~ dt) = 1 - w^2 / (2 (1 + w^2 / 6))")
         if (allocated(error)) return
      end do
      call newmark_frequency(3.5_dp, 1.0_dp/6, 0.5_dp, wt, z, osc)
      call check(error, .not. osc .and. wt == 0.0_dp, "not oscillating beyond sqrt(12) (unstable)")
   end subroutine test_linear

   subroutine test_damped(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: w, wt, z, gamma, beta
      logical :: osc

      gamma = 0.6_dp
      beta = 0.25_dp*(gamma + 0.5_dp)**2
      w = 1.0e-3_dp
      call newmark_frequency(w, beta, gamma, wt, z, osc)
      call check(error, osc .and. abs(z/((gamma - 0.5_dp)*w/2) - 1) < 1e-5_dp, &
                 "zeta ~ (gamma - 1/2) omega dt / 2 at a small step")
   end subroutine test_damped

   !> Free vibration of x'' + w^2 x = 0 (dt = 1) by Newmark's recursion, whose displacements
   !> follow u(k+1) = 2 r cos(th) u(k) - r^2 u(k-1) with r = exp(-zeta wt), th = wt: then
   !> (u(k)^2 - 2 r cos(th) u(k) u(k-1) + r^2 u(k-1)^2) / r^(2k) stays constant. With
   !> newmark_frequency's wt and zeta it does, to about 1e-12 over 20 000 steps; a frequency
   !> off by 1e-9 (relative) moves it by 2e-9.
   subroutine test_recursion(error)
      integer, parameter :: nsteps = 20000
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: cases(3, 5), w, beta, gamma, wt, z, u, v, a, u1, v1, a1, r, q, q0, dev, up
      integer :: i, k
      logical :: osc

      ! w, beta, gamma
      cases(:, 1) = [0.59_dp, 0.25_dp, 0.5_dp]
      cases(:, 2) = [1.7_dp, 0.25_dp, 0.5_dp]
      cases(:, 3) = [0.9_dp, 1.0_dp/6, 0.5_dp]
      cases(:, 4) = [0.3_dp, 0.3025_dp, 0.6_dp]
      cases(:, 5) = [2.5_dp, 0.3025_dp, 0.6_dp]
      do i = 1, size(cases, 2)
         w = cases(1, i); beta = cases(2, i); gamma = cases(3, i)
         call newmark_frequency(w, beta, gamma, wt, z, osc)
         r = exp(-z*wt)
         u = 1.0_dp; v = 0.0_dp; a = -w*w*u
         up = u
         q0 = 0; dev = 0
         do k = 1, nsteps
            u1 = u + v + (0.5_dp - beta)*a
            v1 = v + (1 - gamma)*a
            a1 = -w*w*u1/(1 + beta*w*w)
            u1 = u1 + beta*a1
            v1 = v1 + gamma*a1
            up = u
            u = u1; v = v1; a = a1
            q = (u*u - 2*r*cos(wt)*u*up + r*r*up*up)/r**(2*k)
            if (k == 1) q0 = q
            dev = max(dev, abs(q/q0 - 1))
            if (r**(2*k) < 1e-200_dp) exit
         end do
         call check(error, dev < 1e-10_dp, "the recursion's invariant holds with newmark_frequency's "// &
                    "frequency and damping")
         if (allocated(error)) return
      end do
   end subroutine test_recursion

   !> A hysteretic bearing component (P, mu, f) watched at the deck's P on a mode of mass mr;
   !> the observer sees its N reach 0.5 P and 1.5 P: the spring is 1.5 P mu / f, omega its
   !> mode's, the frequency error average acceleration's 1 - 2 atan(x / 2) / x at x = omega dt1,
   !> the drift |error| omega, the margin's capacity 0.5 P mu; a range that does not grow
   !> leaves the watch as it is.
   subroutine test_observed_force(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(result_type) :: res
      type(ringing_type) :: rg
      real(dp), parameter :: p = 1.0e5_dp, mu = 0.2_dp, f = 1.0e-4_dp, mr = 2.0e4_dp, dt1 = 1.0e-3_dp
      real(dp) :: k, x, e

      model%n_devices = 1
      model%dev = [device_type(law=law_hysteretic, p=p, mu=mu, f=f, partner=2, component=1)]
      res%n_bearings = 1
      res%bearing_n_min = [p]
      res%bearing_n_max = [p]
      res%stick_freq_error = [0.0_dp]
      k = p*mu/f
      rg%n = 1
      rg%dev = [1]
      rg%bearing = [1]
      rg%nrange = reshape([p, p], [2, 1])
      rg%k = [k]
      rg%mr = [mr]
      rg%omega = [sqrt(k/mr)]
      rg%c_fixed = [0.0_dp]
      rg%drift = [0.0_dp]
      rg%pmu = [p*mu]
      rg%pfloor = [p*mu]
      rg%dt1 = dt1
      rg%beta = 0.25_dp
      rg%gamma = 0.5_dp
      call ringing_normal_force(model, rg, res)
      call check(error, rg%k(1) == k .and. res%stick_freq_error(1) == 0.0_dp, "the deck's range kept")
      if (allocated(error)) return
      res%bearing_n_min = [0.5_dp*p]
      res%bearing_n_max = [1.5_dp*p]
      call ringing_normal_force(model, rg, res)
      x = sqrt(1.5_dp*k/mr)*dt1
      e = 1.0_dp - 2.0_dp*atan(x/2.0_dp)/x
      call check(error, abs(rg%k(1) - 1.5_dp*k) <= 1e-12_dp*k, "the spring at the largest N")
      if (allocated(error)) return
      call check(error, abs(res%stick_freq_error(1) - e) <= 1e-9_dp*e, "the frequency error at the largest N")
      if (allocated(error)) return
      call check(error, abs(rg%drift(1) - e*x/dt1) <= 1e-9_dp*e*x/dt1, "the drift at the largest N")
      if (allocated(error)) return
      call check(error, abs(rg%pmu(1) - 0.5_dp*p*mu) <= 1e-12_dp*p*mu .and. rg%pfloor(1) == rg%pmu(1), &
                 "the capacities at the smallest N")
      if (allocated(error)) return
      call check(error, abs(rg%c_fixed(1)) <= 1e-12_dp, "no damping of average acceleration")
   end subroutine test_observed_force

end module test_fd_stick_ringing
