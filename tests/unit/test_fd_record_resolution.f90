!> Unit tests of the two step maps of fd_record_resolution: the exact step of a mode under a
!> load linear in the step (exact_step_map) against closed forms (undamped free vibration, a
!> constant load, a ramp, a damped free vibration, a rigid body), and Newmark's step as a map
!> (newmark_step_map) against the closed form of average acceleration's free vibration (the
!> Cayley transform: the phase advances 2 atan(wn dt / 2) a step, the amplitude is kept) and
!> against linear acceleration run as the recursion itself.
module test_fd_record_resolution
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_record_resolution, only: exact_step_map, newmark_step_map, theta_step_map
   use fd_harmonic_resolution, only: theta_response
   implicit none
   private

   public :: collect_record_resolution

contains

   subroutine collect_record_resolution(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("exact step: undamped free vibration is a rotation", test_free_undamped), &
                  new_unittest("exact step: a constant load and a ramp, undamped", test_loads), &
                  new_unittest("exact step: damped free vibration, under- and overdamped", test_damped), &
                  new_unittest("exact step: a rigid body under a linear load", test_rigid), &
                  new_unittest("Newmark map: average acceleration's phase 2 atan(wn dt / 2)", test_newmark_aa), &
                  new_unittest("Newmark map: the recursion of linear acceleration", test_newmark_recursion), &
                  new_unittest("theta map: its steady state under a harmonic load is theta_response's", &
                               test_theta_map) &
                  ]
   end subroutine collect_record_resolution

   subroutine test_free_undamped(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: phi(2, 2), g0(2), g1(2), wn, h, x
      integer :: i

      do i = 1, 6
         wn = 3.0_dp*i
         h = 0.05_dp*i            ! wn h from 0.15 to 5.4: scaling and squaring at work
         call exact_step_map(wn, 0.0_dp, h, phi, g0, g1)
         x = wn*h
         call check(error, abs(phi(1, 1) - cos(x)) < 1e-13_dp .and. abs(phi(2, 2) - cos(x)) < 1e-13_dp .and. &
                    abs(phi(1, 2) - sin(x)/wn) < 1e-13_dp/wn .and. abs(phi(2, 1) + wn*sin(x)) < 1e-13_dp*wn, &
                    "phi = [cos, sin / wn; -wn sin, cos]")
         if (allocated(error)) return
      end do
   end subroutine test_free_undamped

   subroutine test_loads(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: phi(2, 2), g0(2), g1(2), wn, h, q, v, x

      wn = 7.0_dp
      h = 0.3_dp
      x = wn*h
      call exact_step_map(wn, 0.0_dp, h, phi, g0, g1)
      ! constant load p = 1 from rest: q = (1 - cos wn t) / wn^2, q' = sin(wn t) / wn
      q = g0(1) + g1(1)
      v = g0(2) + g1(2)
      call check(error, abs(q - (1 - cos(x))/wn**2) < 1e-14_dp .and. abs(v - sin(x)/wn) < 1e-14_dp, &
                 "a constant load: (1 - cos wn t) / wn^2")
      if (allocated(error)) return
      ! ramp p = t / h (0 to 1) from rest: q = (t - sin(wn t) / wn) / (wn^2 h)
      q = g1(1)
      v = g1(2)
      call check(error, abs(q - (h - sin(x)/wn)/(wn**2*h)) < 1e-14_dp .and. &
                 abs(v - (1 - cos(x))/(wn**2*h)) < 1e-14_dp, "a ramp: (t - sin(wn t) / wn) / (wn^2 h)")
   end subroutine test_loads

   subroutine test_damped(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), parameter :: xis(3) = [0.05_dp, 0.6_dp, 0.999_dp]
      real(dp) :: phi(2, 2), g0(2), g1(2), wn, xi, h, wd, q, v, r1, r2
      integer :: i

      wn = 12.0_dp
      h = 0.07_dp
      do i = 1, 3
         xi = xis(i)
         call exact_step_map(wn, 2*xi*wn, h, phi, g0, g1)
         ! from q = 1, q' = 0: exp(-xi wn t) (cos wd t + xi wn / wd sin wd t)
         wd = wn*sqrt(1 - xi*xi)
         q = exp(-xi*wn*h)*(cos(wd*h) + xi*wn/wd*sin(wd*h))
         v = -exp(-xi*wn*h)*wn*wn/wd*sin(wd*h)
         call check(error, abs(phi(1, 1) - q) < 1e-13_dp .and. abs(phi(2, 1) - v) < 1e-12_dp, &
                    "underdamped free vibration")
         if (allocated(error)) return
      end do
      ! overdamped, xi = 2: roots r = -xi wn +- wn sqrt(xi^2 - 1); from q = 1, q' = 0
      xi = 2.0_dp
      call exact_step_map(wn, 2*xi*wn, h, phi, g0, g1)
      r1 = -xi*wn + wn*sqrt(xi*xi - 1)
      r2 = -xi*wn - wn*sqrt(xi*xi - 1)
      q = (r2*exp(r1*h) - r1*exp(r2*h))/(r2 - r1)
      call check(error, abs(phi(1, 1) - q) < 1e-13_dp, "overdamped free vibration")
   end subroutine test_damped

   subroutine test_rigid(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: phi(2, 2), g0(2), g1(2), h

      h = 0.4_dp
      call exact_step_map(0.0_dp, 0.0_dp, h, phi, g0, g1)
      ! q(h) = q0 + h q0' + h^2 (p0 / 3 + p1 / 6), q'(h) = q0' + h (p0 + p1) / 2
      call check(error, abs(phi(1, 1) - 1) < 1e-15_dp .and. abs(phi(1, 2) - h) < 1e-15_dp .and. &
                 abs(phi(2, 1)) < 1e-15_dp .and. abs(phi(2, 2) - 1) < 1e-15_dp, "phi of a rigid body")
      if (allocated(error)) return
      call check(error, abs(g0(1) - h*h/3) < 1e-15_dp .and. abs(g1(1) - h*h/6) < 1e-15_dp .and. &
                 abs(g0(2) - h/2) < 1e-15_dp .and. abs(g1(2) - h/2) < 1e-15_dp, "a linear load on a rigid body")
   end subroutine test_rigid

   subroutine test_newmark_aa(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: nm(3, 3), np(3), z(3), wn, h, theta
      integer :: k

      wn = 20.0_dp
      h = 0.06_dp                 ! wn h = 1.2: a phase error of 11 %
      call newmark_step_map(wn, 0.0_dp, h, 0.25_dp, 0.5_dp, nm, np)
      theta = 2*atan(0.5_dp*wn*h)
      z = [1.0_dp, 0.0_dp, -wn*wn]
      do k = 1, 40
         z = matmul(nm, z)
      end do
      call check(error, abs(z(1) - cos(40*theta)) < 1e-12_dp .and. abs(z(2) + wn*sin(40*theta)) < 1e-10_dp, &
                 "q_k = cos(k theta), q'_k = -wn sin(k theta), theta = 2 atan(wn h / 2)")
   end subroutine test_newmark_aa

   subroutine test_newmark_recursion(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: nm(3, 3), np(3), z(3), wn, c, h, beta, gamma, q, v, a, qt, vt, p
      integer :: k

      wn = 9.0_dp
      c = 0.8_dp
      h = 0.02_dp
      beta = 1.0_dp/6
      gamma = 0.5_dp
      call newmark_step_map(wn, c, h, beta, gamma, nm, np)
      z = [0.0_dp, 0.0_dp, 1.0_dp]
      q = 0; v = 0; a = 1
      do k = 1, 200
         p = sin(0.37_dp*k)
         z = matmul(nm, z) + np*p
         qt = q + h*v + (0.5_dp - beta)*h*h*a
         vt = v + (1 - gamma)*h*a
         a = (p - c*vt - wn*wn*qt)/(1 + gamma*h*c + beta*h*h*wn*wn)
         q = qt + beta*h*h*a
         v = vt + gamma*h*a
      end do
      call check(error, abs(z(1) - q) < 1e-13_dp*maxval(abs([q, 1e-3_dp])) .and. abs(z(2) - v) < 1e-12_dp .and. &
                 abs(z(3) - a) < 1e-11_dp, "the map steps as the recursion")
   end subroutine test_newmark_recursion

   !> Moreau-Jean's map run under p = exp(i w t) (real and imaginary parts as two runs) to its
   !> steady state, against the closed form of fd_harmonic_resolution (derived apart, by the
   !> z-transform of the recursion), for three thetas.
   subroutine test_theta_map(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), parameter :: w = 8.0_dp, wn = 10.0_dp, c = 2.0_dp, h = 0.02_dp
      real(dp), parameter :: theta(3) = [0.5_dp, 0.75_dp, 1.0_dp]
      real(dp) :: nm(3, 3), np(3), zr(3), zi(3), pr, pi_
      complex(dp) :: resp, u
      logical :: ok
      integer :: j, n

      do j = 1, 3
         call theta_step_map(wn, c, h, theta(j), nm, np)
         zr = [0.0_dp, 0.0_dp, 1.0_dp]   ! (q, q', p(0)): p = cos(w t)
         zi = [0.0_dp, 0.0_dp, 0.0_dp]   ! p = sin(w t)
         do n = 1, 3000                  ! 60 s: the transient is down by exp(-60)
            pr = cos(w*n*h); pi_ = sin(w*n*h)
            zr = matmul(nm, zr) + np*pr
            zi = matmul(nm, zi) + np*pi_
         end do
         u = cmplx(zr(1), zi(1), dp)/cmplx(pr, pi_, dp)
         call theta_response(w, wn, c, h, theta(j), resp, ok)
         call check(error, ok .and. abs(u - resp) <= 1e-10_dp*abs(resp), "the map's steady state")
         if (allocated(error)) return
      end do
   end subroutine test_theta_map

end module test_fd_record_resolution
