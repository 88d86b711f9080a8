!> Unit tests of the LAPACK/BLAS wrappers (fd_linalg): the Cholesky factorization and solve
!> of the effective stiffness, the symmetric and general products, the LU solve, the
!> generalized eigenproblem and the least-squares solve, against hand-computed results.
module test_fd_linalg
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_linalg, only: cholesky_factor, cholesky_solve, sym_matvec, gen_matvec, lu_solve, &
                        generalized_eigen, least_squares, least_squares_work
   use fd_error, only: fd_error_type => error_type
   use test_fd_helpers, only: check_close, check_matrix
   implicit none
   private

   public :: collect_linalg

contains

   subroutine collect_linalg(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("cholesky factor", test_cholesky_factor), &
                  new_unittest("cholesky solve", test_cholesky_solve), &
                  new_unittest("not positive definite", test_not_spd), &
                  new_unittest("symmetric product", test_sym_matvec), &
                  new_unittest("general product", test_gen_matvec), &
                  new_unittest("lu solve", test_lu_solve), &
                  new_unittest("generalized eigenproblem", test_generalized_eigen), &
                  new_unittest("least squares", test_least_squares) &
                  ]
   end subroutine collect_linalg

   !> A = U' U with U = [[2, 1, -1], [0, 3, 1], [0, 0, 2]]: the factor is exact in binary.
   pure function spd3() result(a)
      real(dp) :: a(3, 3)
      a = reshape([4.0_dp, 2.0_dp, -2.0_dp, 2.0_dp, 10.0_dp, 2.0_dp, -2.0_dp, 2.0_dp, 6.0_dp], [3, 3])
   end function spd3

   subroutine test_cholesky_factor(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(3, 3), u(3, 3)
      integer :: info, i, j

      a = spd3()
      call cholesky_factor(a, info)
      call check(error, info, 0)
      if (allocated(error)) return
      u = reshape([2.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 3.0_dp, 0.0_dp, -1.0_dp, 1.0_dp, 2.0_dp], [3, 3])
      do j = 1, 3
         do i = 1, j
            call check(error, a(i, j), u(i, j), 'Cholesky factor, upper triangle (exact)')
            if (allocated(error)) return
         end do
      end do
   end subroutine test_cholesky_factor

   subroutine test_cholesky_solve(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(3, 3), x(3), b(3)
      integer :: info, i

      a = spd3()
      x = [1.0_dp, -2.0_dp, 0.25_dp]
      b = matmul(a, x)
      call cholesky_factor(a, info)
      call cholesky_solve(a, b)
      do i = 1, 3
         call check_close(error, b(i), x(i), 1.0e-15_dp, 'Cholesky solve of A x = b')
         if (allocated(error)) return
      end do
   end subroutine test_cholesky_solve

   !> [[1, 2], [2, 1]] has eigenvalues 3 and -1: the second leading minor fails.
   subroutine test_not_spd(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(2, 2)
      integer :: info

      a = reshape([1.0_dp, 2.0_dp, 2.0_dp, 1.0_dp], [2, 2])
      call cholesky_factor(a, info)
      call check(error, info, 2, 'indefinite matrix: info names the failing minor')
   end subroutine test_not_spd

   !> Only the upper triangle is read: garbage below the diagonal changes nothing.
   subroutine test_sym_matvec(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(3, 3), x(3), y(3), expected(3)

      a = spd3()
      x = [1.0_dp, 2.0_dp, 3.0_dp]
      expected = 2.0_dp*matmul(a, x) - 0.5_dp*[1.0_dp, 1.0_dp, 1.0_dp]
      a(2, 1) = 1.0e300_dp; a(3, 1) = -7.0_dp; a(3, 2) = 99.0_dp
      y = 1.0_dp
      call sym_matvec(a, x, y, 2.0_dp, -0.5_dp)
      call check_matrix(error, reshape(y, [3, 1]), reshape(expected, [3, 1]), 0.0_dp, &
                        'y = alpha A x + beta y from the upper triangle (exact in binary)')
   end subroutine test_sym_matvec

   subroutine test_gen_matvec(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(2, 3), x(3), y(2), empty(0, 3), y0(0)

      a = reshape([1.0_dp, 4.0_dp, 2.0_dp, 5.0_dp, 3.0_dp, 6.0_dp], [2, 3])
      x = [1.0_dp, 0.0_dp, -1.0_dp]
      y = [10.0_dp, 20.0_dp]
      call gen_matvec(a, x, y, 1.0_dp, 1.0_dp)
      call check_matrix(error, reshape(y, [2, 1]), reshape([8.0_dp, 18.0_dp], [2, 1]), 0.0_dp, &
                        'y = A x + y, rectangular A')
      if (allocated(error)) return
      call gen_matvec(empty, x, y0, 1.0_dp, 0.0_dp)   ! no rows: nothing to do, no BLAS call
   end subroutine test_gen_matvec

   subroutine test_lu_solve(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(3, 3), b(3, 2), x(3, 2), a0(3, 3)
      integer :: ipiv(3), info

      a0 = reshape([0.0_dp, 2.0_dp, 1.0_dp, 1.0_dp, -1.0_dp, 3.0_dp, 4.0_dp, 0.5_dp, -2.0_dp], [3, 3])
      x = reshape([1.0_dp, 2.0_dp, 3.0_dp, -1.0_dp, 0.5_dp, 0.0_dp], [3, 2])
      a = a0
      b = matmul(a0, x)
      call lu_solve(a, b, ipiv, info)   ! a(1, 1) = 0: needs pivoting
      call check(error, info, 0)
      if (allocated(error)) return
      call check_matrix(error, b, x, 1.0e-14_dp, 'LU solve of A X = B, two right-hand sides')
      if (allocated(error)) return
      ! row 2 = 2 row 1: the elimination leaves an exact zero pivot
      a = reshape([1.0_dp, 2.0_dp, 0.0_dp, 2.0_dp, 4.0_dp, 0.0_dp, 3.0_dp, 6.0_dp, 1.0_dp], [3, 3])
      b = 1.0_dp
      call lu_solve(a, b, ipiv, info)
      call check(error, info > 0, 'a singular matrix gives info > 0')
   end subroutine test_lu_solve

   !> Two equal masses on two equal springs in a chain: w^2 = (k/m)(3 -+ sqrt(5))/2, modes
   !> normalized to phi' M phi = 1.
   subroutine test_generalized_eigen(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: k(2, 2), m(2, 2), lam(2), phi(2, 2), gram(2, 2)
      type(fd_error_type), allocatable :: err
      real(dp), parameter :: ks = 1000.0_dp, ms = 2.5_dp

      k = reshape([2.0_dp*ks, -ks, -ks, ks], [2, 2])
      m = reshape([ms, 0.0_dp, 0.0_dp, ms], [2, 2])
      call generalized_eigen(k, m, lam, phi, err)
      call check(error, .not. allocated(err), 'generalized_eigen failed')
      if (allocated(error)) return
      call check_close(error, lam(1), ks/ms*(3.0_dp - sqrt(5.0_dp))/2.0_dp, 1.0e-14_dp, 'first eigenvalue')
      if (allocated(error)) return
      call check_close(error, lam(2), ks/ms*(3.0_dp + sqrt(5.0_dp))/2.0_dp, 1.0e-14_dp, 'second eigenvalue')
      if (allocated(error)) return
      gram = matmul(transpose(phi), matmul(m, phi))
      call check_matrix(error, gram, reshape([1.0_dp, 0.0_dp, 0.0_dp, 1.0_dp], [2, 2]), 1.0e-14_dp, &
                        'modes are M-orthonormal')
      if (allocated(error)) return
      ! first mode: both masses in phase, the upper one moving (1 + sqrt(5))/2 times more
      call check_close(error, phi(2, 1)/phi(1, 1), (1.0_dp + sqrt(5.0_dp))/2.0_dp, 1.0e-14_dp, &
                       'first mode shape')
   end subroutine test_generalized_eigen

   !> An overdetermined consistent system is solved exactly; a rank-deficient one gives the
   !> minimum-norm solution.
   subroutine test_least_squares(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(4, 2), b(4, 1), sv(2), x(2)
      real(dp), allocatable :: work(:)
      integer :: info, i

      allocate (work(least_squares_work(4, 2)))
      a = reshape([1.0_dp, 1.0_dp, 1.0_dp, 1.0_dp, 0.0_dp, 1.0_dp, 2.0_dp, 3.0_dp], [4, 2])
      x = [0.5_dp, -2.0_dp]
      b(:, 1) = matmul(a, x)
      call least_squares(a, b, sv, work, info)
      call check(error, info, 0)
      if (allocated(error)) return
      do i = 1, 2
         call check_close(error, b(i, 1), x(i), 1.0e-14_dp, 'least squares: a line through 4 points')
         if (allocated(error)) return
      end do
      ! x1 + x2 = 2 (twice): the minimum-norm solution is (1, 1)
      a = 0.0_dp
      a(1:2, 1) = 1.0_dp; a(1:2, 2) = 1.0_dp
      b = 0.0_dp
      b(1:2, 1) = 2.0_dp
      call least_squares(a, b, sv, work, info)
      call check_close(error, b(1, 1), 1.0_dp, 1.0e-14_dp, 'least squares: minimum-norm solution')
      if (allocated(error)) return
      call check_close(error, b(2, 1), 1.0_dp, 1.0e-14_dp, 'least squares: minimum-norm solution')
   end subroutine test_least_squares

end module test_fd_linalg
