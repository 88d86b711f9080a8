!> Unit tests of the steady-state response of Newmark's recursion to a sampled harmonic force
!> (fd_harmonic_resolution's newmark_response): the bilinear transform for average
!> acceleration, second-order (gamma = 1/2) and first-order (gamma > 1/2) convergence to the
!> exact response, the recursion itself run step by step to its steady state (an independent
!> computation), and the frequency the steps cannot see; the same for the Moreau-Jean
!> technique's theta-method (theta_response).
module test_fd_harmonic_resolution
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_harmonic_resolution, only: newmark_response, theta_response
   implicit none
   private

   public :: collect_harmonic_resolution

   real(dp), parameter :: pi = acos(-1.0_dp)

contains

   subroutine collect_harmonic_resolution(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("average acceleration: the bilinear transform", test_bilinear), &
                  new_unittest("converges to the exact response: order 2, order 1 for gamma > 1/2", test_order), &
                  new_unittest("the steady state of the recursion run step by step", test_recursion), &
                  new_unittest("w dt = 2 pi: the steps see a constant force", test_aliased), &
                  new_unittest("Moreau-Jean's theta-method: its recursion's steady state, theta = 1/2 "// &
                               "is average acceleration, order 1 for theta > 1/2", test_theta) &
                  ]
   end subroutine collect_harmonic_resolution

   pure complex(dp) function exact(w, wn, xi)
      real(dp), intent(in) :: w, wn, xi
      exact = 1.0_dp/cmplx(wn*wn - w*w, 2.0_dp*xi*wn*w, dp)
   end function exact

   subroutine test_bilinear(error)
      type(error_type), allocatable, intent(out) :: error
      complex(dp) :: h, b
      real(dp) :: w, wn, dt, om
      logical :: ok
      integer :: i, j

      wn = 10.0_dp
      do i = 1, 12
         do j = 1, 5
            w = 2.5_dp*i
            dt = 0.01_dp*j
            call newmark_response(w, wn, 2*0.03_dp*wn, dt, 0.25_dp, 0.5_dp, h, ok)
            om = 2.0_dp/dt*tan(0.5_dp*w*dt)
            b = 1.0_dp/cmplx(wn*wn - om*om, 2.0_dp*0.03_dp*wn*om, dp)
            call check(error, ok .and. abs(h - b) <= 1e-12_dp*abs(b), "U / P = exact response at (2 / dt) tan(w dt / 2)")
            if (allocated(error)) return
         end do
      end do
   end subroutine test_bilinear

   subroutine test_order(error)
      type(error_type), allocatable, intent(out) :: error
      complex(dp) :: h1, h2, e
      real(dp) :: r
      logical :: ok

      e = exact(9.0_dp, 10.0_dp, 0.05_dp)
      call newmark_response(9.0_dp, 10.0_dp, 1.0_dp, 2e-3_dp, 0.25_dp, 0.5_dp, h1, ok)
      call newmark_response(9.0_dp, 10.0_dp, 1.0_dp, 1e-3_dp, 0.25_dp, 0.5_dp, h2, ok)
      r = abs(h1 - e)/abs(h2 - e)
      call check(error, abs(r - 4.0_dp) < 0.01_dp, "average acceleration: halving dt quarters the error")
      if (allocated(error)) return
      call newmark_response(9.0_dp, 10.0_dp, 1.0_dp, 2e-3_dp, 0.3025_dp, 0.6_dp, h1, ok)
      call newmark_response(9.0_dp, 10.0_dp, 1.0_dp, 1e-3_dp, 0.3025_dp, 0.6_dp, h2, ok)
      r = abs(h1 - e)/abs(h2 - e)
      call check(error, abs(r - 2.0_dp) < 0.02_dp, "gamma = 0.6: halving dt halves the error")
   end subroutine test_order

   !> m u'' + c u' + k u = exp(i w t), m = 1, by Newmark's recursion: after the transient
   !> (damped as exp(-xi wn t)), u_n exp(-i w t_n) is the steady-state response.
   subroutine test_recursion(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), parameter :: w = 8.0_dp, wn = 10.0_dp, xi = 0.1_dp, dt = 0.02_dp
      real(dp) :: beta(3), gamma(3)
      complex(dp) :: u, v, a, u1, a1, p1, h
      logical :: ok
      integer :: r, n

      beta = [0.25_dp, 1.0_dp/6.0_dp, 0.3025_dp]
      gamma = [0.5_dp, 0.5_dp, 0.6_dp]
      do r = 1, 3
         u = 0; v = 0; a = 1.0_dp           ! a(0) from equilibrium with p(0) = 1
         do n = 1, 6000                     ! 120 s: the transient is down by exp(-120)
            p1 = exp(cmplx(0.0_dp, w*n*dt, dp))
            ! (1 + gamma dt c + beta dt^2 k) a1 = p1 - c (v + (1 - gamma) dt a) - k (u + dt v + (1/2 - beta) dt^2 a)
            a1 = (p1 - 2*xi*wn*(v + (1 - gamma(r))*dt*a) - wn*wn*(u + dt*v + (0.5_dp - beta(r))*dt*dt*a)) &
                 /(1 + gamma(r)*dt*2*xi*wn + beta(r)*dt*dt*wn*wn)
            u1 = u + dt*v + dt*dt*((0.5_dp - beta(r))*a + beta(r)*a1)
            v = v + dt*((1 - gamma(r))*a + gamma(r)*a1)
            u = u1; a = a1
         end do
         call newmark_response(w, wn, 2*xi*wn, dt, beta(r), gamma(r), h, ok)
         call check(error, ok .and. abs(u/p1 - h) <= 1e-10_dp*abs(h), "the recursion's steady state")
         if (allocated(error)) return
      end do
   end subroutine test_recursion

   !> m u'' + c u' + k u = exp(i w t), m = 1, by the theta-method of fd_moreau_jean (force
   !> interpolated as v and u): its steady state, against theta_response; theta = 1/2 is the
   !> bilinear transform (Newmark's average acceleration); theta = 1 converges at order 1.
   subroutine test_theta(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), parameter :: w = 8.0_dp, wn = 10.0_dp, xi = 0.1_dp, dt = 0.02_dp
      real(dp), parameter :: theta(3) = [0.5_dp, 0.75_dp, 1.0_dp]
      complex(dp) :: u, v, p0, p1, vt, h, hn, e, h1, h2
      real(dp) :: c, r
      logical :: ok
      integer :: j, n

      c = 2*xi*wn
      do j = 1, 3
         u = 0; v = 0; p0 = 1.0_dp
         do n = 1, 6000                     ! 120 s: the transient is down by exp(-120)
            p1 = exp(cmplx(0.0_dp, w*n*dt, dp))
            ! v_theta (1 + theta dt c + theta^2 dt^2 wn^2) = v + theta dt (p_theta - wn^2 u)
            vt = (v + theta(j)*dt*(((1 - theta(j))*p0 + theta(j)*p1) - wn*wn*u)) &
                 /(1 + theta(j)*dt*c + (theta(j)*dt*wn)**2)
            u = u + dt*vt
            v = (vt - (1 - theta(j))*v)/theta(j)
            p0 = p1
         end do
         call theta_response(w, wn, c, dt, theta(j), h, ok)
         call check(error, ok .and. abs(u/p1 - h) <= 1e-10_dp*abs(h), "the theta recursion's steady state")
         if (allocated(error)) return
      end do
      call theta_response(w, wn, c, dt, 0.5_dp, h, ok)
      call newmark_response(w, wn, c, dt, 0.25_dp, 0.5_dp, hn, ok)
      call check(error, abs(h - hn) <= 1e-13_dp*abs(hn), "theta = 1/2: average acceleration's response")
      if (allocated(error)) return
      e = exact(9.0_dp, 10.0_dp, 0.05_dp)
      call theta_response(9.0_dp, 10.0_dp, 1.0_dp, 5e-4_dp, 1.0_dp, h1, ok)   ! asymptotic: 1.99
      call theta_response(9.0_dp, 10.0_dp, 1.0_dp, 2.5e-4_dp, 1.0_dp, h2, ok)
      r = abs(h1 - e)/abs(h2 - e)
      call check(error, abs(r - 2.0_dp) < 0.02_dp, "theta = 1: halving dt halves the error")
   end subroutine test_theta

   subroutine test_aliased(error)
      type(error_type), allocatable, intent(out) :: error
      complex(dp) :: h
      logical :: ok

      call newmark_response(2*pi/0.01_dp, 10.0_dp, 1.0_dp, 0.01_dp, 0.25_dp, 0.5_dp, h, ok)
      call check(error, .not. ok, "w dt = 2 pi: not resolved at all")
   end subroutine test_aliased

end module test_fd_harmonic_resolution
