!> Unit tests of the polynomial kernels of the exact technique (fd_taylor) on polynomials
!> with known zeros: the Taylor shift, the lower bound, Descartes' count after the Moebius
!> map, the first crossing (close pairs of zeros a sampling grid steps over, a touch that
!> is no crossing, a degree-24 Taylor polynomial of cos) and the stationary points.
module test_fd_taylor
   use testdrive, only: new_unittest, unittest_type, error_type, check, test_failed
   use fd_kinds, only: dp
   use fd_taylor, only: poly_value, poly_value_deriv, poly_shift, poly_abs_bound, poly_lower_bound, &
                        descartes_count, first_crossing, stationary_points, polish_zero, max_depth
   use test_fd_helpers, only: check_close
   implicit none
   private

   public :: collect_taylor

   real(dp), parameter :: pi = acos(-1.0_dp)

contains

   subroutine collect_taylor(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("Horner value and derivative", test_value), &
                  new_unittest("Taylor shift", test_shift), &
                  new_unittest("lower bound below the minimum", test_lower_bound), &
                  new_unittest("Descartes count after the Moebius map", test_descartes), &
                  new_unittest("polished zero", test_polish), &
                  new_unittest("first crossing of a close pair of zeros", test_close_pair), &
                  new_unittest("a touch is no crossing", test_touch), &
                  new_unittest("first crossing of a Taylor polynomial of cos", test_cos), &
                  new_unittest("no crossing", test_no_crossing), &
                  new_unittest("stationary points of a Taylor polynomial of sin", test_stationary), &
                  new_unittest("stationary points of a cubic and a constant", test_stationary_small) &
                  ]
   end subroutine collect_taylor

   !> Coefficients of prod_i (s - r_i) times f (degree size(r)).
   pure subroutine from_roots(r, f, c)
      real(dp), intent(in) :: r(:), f
      real(dp), intent(out) :: c(0:)
      integer :: i, k

      c = 0.0_dp
      c(0) = f
      do i = 1, size(r)
         do k = i, 1, -1
            c(k) = c(k - 1) - r(i)*c(k)
         end do
         c(0) = -r(i)*c(0)
      end do
   end subroutine from_roots

   !> Taylor coefficients of cos(w s + phi) of degree n.
   pure subroutine trig_taylor(w, phi, c)
      real(dp), intent(in) :: w, phi
      real(dp), intent(out) :: c(0:)
      integer :: k
      real(dp) :: f

      f = 1.0_dp
      do k = 0, ubound(c, 1)
         if (k > 0) f = f*w/k
         c(k) = f*cos(phi + k*pi/2.0_dp)
      end do
   end subroutine trig_taylor

   subroutine test_value(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: c(0:3), v, dv

      c = [1.0_dp, -2.0_dp, 0.5_dp, 3.0_dp]
      call poly_value_deriv(c, 0.7_dp, v, dv)
      call check_close(error, v, 1.0_dp - 1.4_dp + 0.5_dp*0.49_dp + 3.0_dp*0.343_dp, 1e-15_dp, "p(0.7)")
      if (allocated(error)) return
      call check_close(error, dv, -2.0_dp + 0.7_dp + 9.0_dp*0.49_dp, 1e-15_dp, "p'(0.7)")
      if (allocated(error)) return
      call check_close(error, poly_value(c, 0.7_dp), v, 0.0_dp, "poly_value = poly_value_deriv")
      if (allocated(error)) return
      call check_close(error, poly_abs_bound(c, 2.0_dp), 1.0_dp + 4.0_dp + 2.0_dp + 24.0_dp, 0.0_dp, "abs bound")
   end subroutine test_value

   subroutine test_shift(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: c(0:12), d(0:12)
      integer :: i

      call trig_taylor(3.0_dp, 0.3_dp, c)
      call poly_shift(c, 0.4_dp, d)
      do i = 0, 10
         call check_close(error, poly_value(d, 0.05_dp*i), poly_value(c, 0.4_dp + 0.05_dp*i), 1e-14_dp, &
                          "p(s + h) by the shifted coefficients")
         if (allocated(error)) return
      end do
   end subroutine test_shift

   subroutine test_lower_bound(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: c(0:8), lb, pmin
      integer :: i, j

      do j = 1, 4
         call trig_taylor(2.0_dp*j, 0.7_dp*j, c)
         c(0) = c(0) + 0.1_dp*j
         lb = poly_lower_bound(c, 0.5_dp)
         pmin = huge(1.0_dp)
         do i = 0, 1000
            pmin = min(pmin, poly_value(c, 0.5_dp*i/1000.0_dp))
         end do
         call check(error, lb <= pmin, "lower bound above the minimum")
         if (allocated(error)) return
      end do
      ! a convex quadratic: the bound is its minimum
      c = 0.0_dp
      c(0:2) = [1.0_dp, -2.0_dp, 2.0_dp]
      call check_close(error, poly_lower_bound(c, 1.0_dp), 0.5_dp, 1e-15_dp, "minimum of 1 - 2s + 2s^2")
   end subroutine test_lower_bound

   subroutine test_descartes(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: c(0:3), wk(0:3)
      integer :: nv

      call from_roots([0.2_dp, 0.5_dp, 1.5_dp], 1.0_dp, c)
      call descartes_count(c, 1.0_dp, wk, nv)
      call check(error, nv, 2, "two zeros in (0, 1)")
      if (allocated(error)) return
      call descartes_count(c, 0.3_dp, wk, nv)
      call check(error, nv, 1, "one zero in (0, 0.3)")
      if (allocated(error)) return
      call descartes_count(c, 0.1_dp, wk, nv)
      call check(error, nv, 0, "none in (0, 0.1)")
      if (allocated(error)) return
      call descartes_count(c, 2.0_dp, wk, nv)
      call check(error, nv, 3, "three in (0, 2)")
   end subroutine test_descartes

   subroutine test_polish(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: c(0:3), r

      call from_roots([0.2_dp, 0.5_dp, 1.5_dp], -1.0_dp, c)   ! -(s-0.2)(s-0.5)(s-1.5): > 0 at 0
      r = polish_zero(c, 1.0_dp, 0.0_dp, 0.3_dp, 1e-15_dp)
      call check_close(error, r, 0.2_dp, 1e-14_dp, "zero 0.2")
      if (allocated(error)) return
      call check(error, poly_value(c, r) <= 0.0_dp, "the returned end has p <= 0")
      if (allocated(error)) return
      r = polish_zero(c, -1.0_dp, 0.3_dp, 1.0_dp, 1e-15_dp)
      call check_close(error, r, 0.5_dp, 1e-14_dp, "zero 0.5 of -p")
   end subroutine test_polish

   !> Two zeros 1e-7 apart in a dip of depth 2.1e-15 that no grid coarser than 1e-7 sees.
   !> The first is found; its position is conditioned by the slope there, 8.5e-8: a
   !> rounding of 1e-16 in p moves it by 1.2e-9 (measured error 1.6e-10).
   subroutine test_close_pair(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: c(0:4), wk(0:4, 0:max_depth), w2(0:4), s
      logical :: found

      call from_roots([0.3_dp, 0.3_dp + 1e-7_dp, 0.8_dp, 2.0_dp], 1.0_dp, c)
      call first_crossing(c, 1.0_dp, 1e-15_dp, 1e-16_dp, wk, w2, s, found)
      call check(error, found, "crossing found")
      if (allocated(error)) return
      call check_close(error, s, 0.3_dp, 2e-9_dp, "first of the pair")
      if (allocated(error)) return
      call check(error, s < 0.3_dp + 0.5e-7_dp, "the first zero of the pair, not the second")
   end subroutine test_close_pair

   !> (s - 0.4)^2 + 1e-13 never reaches 0; (s - 0.4)^2 (0.9 - s) touches 0 at 0.4 and
   !> crosses at 0.9.
   subroutine test_touch(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: c(0:3), wk(0:3, 0:max_depth), w2(0:3), s
      logical :: found

      c = 0.0_dp
      c(0:2) = [0.16_dp + 1e-13_dp, -0.8_dp, 1.0_dp]
      call first_crossing(c(0:2), 1.0_dp, 1e-15_dp, 1e-16_dp, wk(0:2, :), w2(0:2), s, found)
      call check(error, .not. found, "no crossing above the axis")
      if (allocated(error)) return
      call from_roots([0.4_dp, 0.4_dp, 0.9_dp], -1.0_dp, c)
      call first_crossing(c, 1.0_dp, 1e-15_dp, 1e-16_dp, wk, w2, s, found)
      call check(error, found, "crossing found")
      if (allocated(error)) return
      ! the touch at 0.4 is computed to be <= 0 within rounding, or is passed over
      if (abs(s - 0.4_dp) > 1e-6_dp) then
         call check_close(error, s, 0.9_dp, 1e-13_dp, "crossing at 0.9 after the touch")
      end if
   end subroutine test_touch

   !> cos(7 s + 0.2) to degree 30 on [0, 1]: first zero (pi/2 - 0.2) / 7.
   subroutine test_cos(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: c(0:30), wk(0:30, 0:max_depth), w2(0:30), s
      logical :: found

      call trig_taylor(7.0_dp, 0.2_dp, c)
      call first_crossing(c, 1.0_dp, 1e-15_dp, 1e-16_dp, wk, w2, s, found)
      call check(error, found, "crossing found")
      if (allocated(error)) return
      call check_close(error, s, (pi/2.0_dp - 0.2_dp)/7.0_dp, 1e-13_dp, "first zero of cos")
   end subroutine test_cos

   subroutine test_no_crossing(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: c(0:30), wk(0:30, 0:max_depth), w2(0:30), s
      logical :: found

      call trig_taylor(7.0_dp, 0.2_dp, c)
      c(0) = c(0) + 1.0_dp + 1e-9_dp     ! 1 + 1e-9 + cos > 0
      call first_crossing(c, 1.0_dp, 1e-15_dp, 1e-16_dp, wk, w2, s, found)
      call check(error, .not. found, "no crossing of 1 + 1e-9 + cos")
   end subroutine test_no_crossing

   !> sin(4 s + 0.1) to degree 34 on [0, 1.2]: p' = 4 cos(4 s + 0.1) vanishes at
   !> (pi/2 + k pi - 0.1) / 4, k = 0, 1; and p with p' = (s - 0.1)(s - 0.35)(s - 0.36)(s - 0.9).
   subroutine test_stationary(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: c(0:34), wk(0:34, 0:max_depth), w2(0:34), roots(10), d(0:3), r4(4)
      integer :: nr, k

      call trig_taylor(4.0_dp, 0.1_dp - pi/2.0_dp, c)
      call stationary_points(c, 1.2_dp, 1e-15_dp, 1e-16_dp, wk, w2, roots, nr)
      call check(error, nr, 2, "two stationary points")
      if (allocated(error)) return
      do k = 0, 1
         call check_close(error, roots(k + 1), (pi/2.0_dp + k*pi - 0.1_dp)/4.0_dp, 1e-13_dp, "stationary point")
         if (allocated(error)) return
      end do
      r4 = [0.1_dp, 0.35_dp, 0.36_dp, 0.9_dp]
      call from_roots(r4, 1.0_dp, c(0:4))
      d(0:3) = c(0:3)
      c(0) = 0.7_dp
      do k = 1, 4
         c(k) = d(k - 1)/k
      end do
      c(5) = 1.0_dp/5.0_dp
      call stationary_points(c(0:5), 1.0_dp, 1e-15_dp, 1e-16_dp, wk(0:5, :), w2(0:5), roots, nr)
      call check(error, nr, 4, "four stationary points")
      if (allocated(error)) return
      do k = 1, 4
         call check_close(error, roots(k), r4(k), 1e-13_dp, "stationary point of the quintic")
         if (allocated(error)) return
      end do
   end subroutine test_stationary

   subroutine test_stationary_small(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: c(0:3), wk(0:3, 0:max_depth), w2(0:3), roots(4)
      integer :: nr

      ! p = s^3/3 - 0.65 s^2 + 0.1 s: p' = (s - 0.2)(s - 1.1)... only 0.2 in (0, 1)
      c = [0.0_dp, 0.22_dp, -0.65_dp, 1.0_dp/3.0_dp]
      call stationary_points(c, 1.0_dp, 1e-15_dp, 1e-16_dp, wk, w2, roots, nr)
      call check(error, nr, 1, "one stationary point in (0, 1)")
      if (allocated(error)) return
      call check_close(error, roots(1), 0.2_dp, 1e-14_dp, "stationary point 0.2")
      if (allocated(error)) return
      c = [2.0_dp, 0.0_dp, 0.0_dp, 0.0_dp]
      call stationary_points(c, 1.0_dp, 1e-15_dp, 1e-16_dp, wk, w2, roots, nr)
      call check(error, nr, 0, "a constant has none")
   end subroutine test_stationary_small

end module test_fd_taylor
