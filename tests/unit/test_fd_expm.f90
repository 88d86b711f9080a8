!> Unit tests of the matrix exponential and the Van Loan propagators (fd_expm) against
!> closed forms. Tolerances: measured errors (FD_UNIT_REPORT=1) times 10 to 100, stated
!> at each check; the Pade approximant of degree 13 is accurate to round-off for
!> ||A|| <= 5.37, and each squaring of the scaled exponential adds about an ulp times ||A||.
module test_fd_expm
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_expm, only: expm, lti_propagators
   use test_fd_helpers, only: check_close, check_matrix
   implicit none
   private

   public :: collect_expm

contains

   subroutine collect_expm(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("rotation generator", test_rotation), &
                  new_unittest("nilpotent matrix", test_nilpotent), &
                  new_unittest("diagonal matrix", test_diagonal), &
                  new_unittest("scaling and squaring", test_scaling), &
                  new_unittest("scalar propagators", test_scalar_propagators), &
                  new_unittest("propagator identities", test_propagator_identities), &
                  new_unittest("empty system", test_empty) &
                  ]
   end subroutine collect_expm

   !> exp([[0, -t], [t, 0]]) is the rotation by t: small t (no scaling), t = 40 (3 squarings).
   subroutine test_rotation(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(2, 2), e(2, 2), r(2, 2), theta(2), tol(2)
      integer :: info, i

      theta = [1.3_dp, 40.0_dp]
      tol = [1.0e-14_dp, 1.0e-13_dp]
      do i = 1, 2
         a = reshape([0.0_dp, theta(i), -theta(i), 0.0_dp], [2, 2])
         r = reshape([cos(theta(i)), sin(theta(i)), -sin(theta(i)), cos(theta(i))], [2, 2])
         call expm(a, e, info)
         call check(error, info, 0)
         if (allocated(error)) return
         call check_matrix(error, e, r, tol(i), 'exp of a rotation generator')
         if (allocated(error)) return
      end do
      ! and it is orthogonal: e' e = I
      call check_matrix(error, matmul(transpose(e), e), reshape([1.0_dp, 0.0_dp, 0.0_dp, 1.0_dp], [2, 2]), &
                        1.0e-13_dp, 'exp of a rotation generator is orthogonal')
   end subroutine test_rotation

   !> A strictly upper triangular N (N**4 = 0): exp(N) = I + N + N**2/2 + N**3/6 exactly,
   !> with a norm that needs scaling (squaring a nilpotent exponential is exact in theory).
   subroutine test_nilpotent(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: n(4, 4), e(4, 4), expected(4, 4), n2(4, 4)
      integer :: info, i

      n = 0.0_dp
      n(1, 2) = 2.0_dp; n(1, 3) = -1.0_dp; n(1, 4) = 3.0_dp
      n(2, 3) = 4.0_dp; n(2, 4) = 0.5_dp; n(3, 4) = -6.0_dp
      n2 = matmul(n, n)
      expected = n + n2/2.0_dp + matmul(n2, n)/6.0_dp
      do i = 1, 4
         expected(i, i) = expected(i, i) + 1.0_dp
      end do
      call expm(n, e, info)
      call check(error, info, 0)
      if (allocated(error)) return
      call check_matrix(error, e, expected, 1.0e-14_dp, 'exp of a nilpotent matrix')
   end subroutine test_nilpotent

   !> exp(diag(d)) = diag(exp(d)), each entry to its own relative accuracy (norm 30: scaled;
   !> exp(-30) after three squarings is off by 3.5e-14 relative).
   subroutine test_diagonal(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(4, 4), e(4, 4), d(4)
      integer :: info, i, j

      d = [-30.0_dp, -1.0_dp, 0.5_dp, 2.0_dp]
      a = 0.0_dp
      do i = 1, 4
         a(i, i) = d(i)
      end do
      call expm(a, e, info)
      call check(error, info, 0)
      if (allocated(error)) return
      do i = 1, 4
         call check_close(error, e(i, i), exp(d(i)), 1.0e-12_dp, 'exp of a diagonal matrix: diagonal')
         if (allocated(error)) return
         do j = 1, 4
            if (j == i) cycle
            call check(error, e(i, j) == 0.0_dp, 'exp of a diagonal matrix is diagonal')
            if (allocated(error)) return
         end do
      end do
   end subroutine test_diagonal

   !> A non-normal matrix of norm 102 (five squarings): exp([[a, b], [0, c]]) =
   !> [[e^a, b (e^a - e^c)/(a - c)], [0, e^c]]; and exp(A) exp(-A) = I for a full 3x3 matrix.
   subroutine test_scaling(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(2, 2), e(2, 2), f(3, 3), ef(3, 3), emf(3, 3), eye(3, 3)
      real(dp), parameter :: p = -1.0_dp, q = -2.0_dp, b = 100.0_dp
      integer :: info, i

      a = reshape([p, 0.0_dp, b, q], [2, 2])
      call expm(a, e, info)
      call check(error, info, 0)
      if (allocated(error)) return
      call check_close(error, e(1, 1), exp(p), 1.0e-13_dp, 'exp of [[a, b], [0, c]]: (1, 1)')
      if (allocated(error)) return
      call check_close(error, e(2, 2), exp(q), 1.0e-13_dp, 'exp of [[a, b], [0, c]]: (2, 2)')
      if (allocated(error)) return
      call check_close(error, e(1, 2), b*(exp(p) - exp(q))/(p - q), 1.0e-13_dp, 'exp of [[a, b], [0, c]]: (1, 2)')
      if (allocated(error)) return
      call check(error, e(2, 1) == 0.0_dp, 'exp of an upper triangular matrix is upper triangular')
      if (allocated(error)) return
      f = reshape([1.5_dp, -7.0_dp, 3.0_dp, 4.0_dp, -2.0_dp, 9.0_dp, -5.0_dp, 6.0_dp, 0.5_dp], [3, 3])
      call expm(f, ef, info)
      call expm(-f, emf, info)
      eye = 0.0_dp
      do i = 1, 3
         eye(i, i) = 1.0_dp
      end do
      call check_matrix(error, matmul(ef, emf), eye, 1.0e-10_dp, 'exp(A) exp(-A) = I, ||A|| = 18')
   end subroutine test_scaling

   !> x' = a x + g: phi = e^(a tau), gam1 = (e^(a tau) - 1)/a, gam2 = (e^(a tau) - 1 - a tau)/a^2;
   !> a = 0: gam1 = tau, gam2 = tau^2/2. (a tau = -12 needs two squarings: phi 8.7e-15 off.)
   subroutine test_scalar_propagators(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(1, 1), phi(1, 1), g1(1, 1), g2(1, 1), tau, x
      integer :: info, i
      real(dp), parameter :: rates(3) = [-2.5_dp, 0.8_dp, -40.0_dp]

      tau = 0.3_dp
      do i = 1, size(rates)
         a = rates(i)
         x = rates(i)*tau
         call lti_propagators(a, tau, phi, g1, g2, info)
         call check(error, info, 0)
         if (allocated(error)) return
         call check_close(error, phi(1, 1), exp(x), 1.0e-13_dp, 'scalar phi = exp(a tau)')
         if (allocated(error)) return
         call check_close(error, g1(1, 1), (exp(x) - 1.0_dp)/rates(i), 1.0e-14_dp, 'scalar gam1')
         if (allocated(error)) return
         call check_close(error, g2(1, 1), (exp(x) - 1.0_dp - x)/rates(i)**2, 1.0e-13_dp, 'scalar gam2')
         if (allocated(error)) return
      end do
      a = 0.0_dp
      call lti_propagators(a, tau, phi, g1, g2, info)
      call check(error, phi(1, 1) == 1.0_dp, 'phi of a = 0 is 1')
      if (allocated(error)) return
      call check_close(error, g1(1, 1), tau, 1.0e-15_dp, 'gam1 of a = 0 is tau')
      if (allocated(error)) return
      call check_close(error, g2(1, 1), tau**2/2.0_dp, 1.0e-15_dp, 'gam2 of a = 0 is tau^2/2')
   end subroutine test_scalar_propagators

   !> For any A: A gam1 = phi - I and A gam2 = gam1 - tau I (integrate by parts), and phi of
   !> two half steps is phi of the whole step. A: a damped 2-DOF oscillator in state form.
   subroutine test_propagator_identities(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(4, 4), phi(4, 4), g1(4, 4), g2(4, 4), ph(4, 4), h1(4, 4), h2(4, 4), eye(4, 4)
      real(dp), parameter :: tau = 0.01_dp
      integer :: info, i

      a = 0.0_dp
      a(1, 3) = 1.0_dp; a(2, 4) = 1.0_dp
      ! M = diag(6.301, 2.530), K = [[k1 + k2, -k2], [-k2, k2]], C = 0.002 K
      a(3, 1:2) = -[1084.0_dp + 2895.0_dp, -2895.0_dp]/6.301_dp
      a(4, 1:2) = -[-2895.0_dp, 2895.0_dp]/2.530_dp
      a(3, 3:4) = 0.002_dp*a(3, 1:2)
      a(4, 3:4) = 0.002_dp*a(4, 1:2)
      eye = 0.0_dp
      do i = 1, 4
         eye(i, i) = 1.0_dp
      end do
      call lti_propagators(a, tau, phi, g1, g2, info)
      call check(error, info, 0)
      if (allocated(error)) return
      call check_matrix(error, matmul(a, g1), phi - eye, 1.0e-13_dp, 'A gam1 = phi - I')
      if (allocated(error)) return
      call check_matrix(error, matmul(a, g2), g1 - tau*eye, 1.0e-12_dp, 'A gam2 = gam1 - tau I')
      if (allocated(error)) return
      call lti_propagators(a, tau/2.0_dp, ph, h1, h2, info)
      call check_matrix(error, matmul(ph, ph), phi, 1.0e-14_dp, 'phi(tau/2)**2 = phi(tau)')
      if (allocated(error)) return
      ! gam1(tau) = gam1(tau/2) + phi(tau/2) gam1(tau/2)
      call check_matrix(error, h1 + matmul(ph, h1), g1, 1.0e-14_dp, 'gam1 over two half steps')
   end subroutine test_propagator_identities

   subroutine test_empty(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(0, 0), e(0, 0)
      integer :: info

      info = -1
      call expm(a, e, info)
      call check(error, info, 0)
   end subroutine test_empty

end module test_fd_expm
