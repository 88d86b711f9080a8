!> Thin wrappers over the LAPACK and BLAS routines frictiondyn uses: Cholesky
!> factorization and solve of the effective stiffness, symmetric matrix-vector products,
!> and the generalized symmetric eigenproblem K phi = w^2 M phi.
module fd_linalg
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int
   implicit none
   private

   public :: cholesky_factor, cholesky_solve, sym_matvec, gen_matvec, generalized_eigen

   interface
      subroutine dpotrf(uplo, n, a, lda, info)
         import :: dp
         character(len=1), intent(in) :: uplo
         integer, intent(in) :: n, lda
         real(dp), intent(inout) :: a(lda, *)
         integer, intent(out) :: info
      end subroutine dpotrf
      subroutine dpotrs(uplo, n, nrhs, a, lda, b, ldb, info)
         import :: dp
         character(len=1), intent(in) :: uplo
         integer, intent(in) :: n, nrhs, lda, ldb
         real(dp), intent(in) :: a(lda, *)
         real(dp), intent(inout) :: b(ldb, *)
         integer, intent(out) :: info
      end subroutine dpotrs
      subroutine dsymv(uplo, n, alpha, a, lda, x, incx, beta, y, incy)
         import :: dp
         character(len=1), intent(in) :: uplo
         integer, intent(in) :: n, lda, incx, incy
         real(dp), intent(in) :: alpha, beta
         real(dp), intent(in) :: a(lda, *), x(*)
         real(dp), intent(inout) :: y(*)
      end subroutine dsymv
      subroutine dgemv(trans, m, n, alpha, a, lda, x, incx, beta, y, incy)
         import :: dp
         character(len=1), intent(in) :: trans
         integer, intent(in) :: m, n, lda, incx, incy
         real(dp), intent(in) :: alpha, beta
         real(dp), intent(in) :: a(lda, *), x(*)
         real(dp), intent(inout) :: y(*)
      end subroutine dgemv
      subroutine dsygv(itype, jobz, uplo, n, a, lda, b, ldb, w, work, lwork, info)
         import :: dp
         integer, intent(in) :: itype, n, lda, ldb, lwork
         character(len=1), intent(in) :: jobz, uplo
         real(dp), intent(inout) :: a(lda, *), b(ldb, *)
         real(dp), intent(out) :: w(*), work(*)
         integer, intent(out) :: info
      end subroutine dsygv
   end interface

contains

   !> Cholesky factorization in place (upper triangle) of a symmetric positive definite matrix.
   subroutine cholesky_factor(a, info)
      real(dp), intent(inout) :: a(:, :) !! matrix on entry, its factor on exit
      integer, intent(out) :: info       !! 0, or the order of the failing leading minor

      call dpotrf('U', size(a, 1), a, size(a, 1), info)
   end subroutine cholesky_factor

   !> Solve A x = b with the factor from cholesky_factor; b is overwritten by x.
   subroutine cholesky_solve(a, b)
      real(dp), intent(in) :: a(:, :)   !! Cholesky factor
      real(dp), intent(inout) :: b(:)   !! right-hand side on entry, solution on exit
      integer :: info

      call dpotrs('U', size(a, 1), 1, a, size(a, 1), b, size(b), info)
   end subroutine cholesky_solve

   !> y = alpha A x + beta y for a symmetric A (upper triangle used).
   subroutine sym_matvec(a, x, y, alpha, beta)
      real(dp), intent(in) :: a(:, :)   !! symmetric matrix
      real(dp), intent(in) :: x(:)      !! vector
      real(dp), intent(inout) :: y(:)   !! result
      real(dp), intent(in) :: alpha     !! factor of A x
      real(dp), intent(in) :: beta      !! factor of the incoming y

      call dsymv('U', size(a, 1), alpha, a, size(a, 1), x, 1, beta, y, 1)
   end subroutine sym_matvec

   !> y = alpha A x + beta y for a general A.
   subroutine gen_matvec(a, x, y, alpha, beta)
      real(dp), intent(in) :: a(:, :)   !! matrix (m x n)
      real(dp), intent(in) :: x(:)      !! vector (n)
      real(dp), intent(inout) :: y(:)   !! result (m)
      real(dp), intent(in) :: alpha     !! factor of A x
      real(dp), intent(in) :: beta      !! factor of the incoming y

      if (size(a, 1) == 0) return
      call dgemv('N', size(a, 1), size(a, 2), alpha, a, size(a, 1), x, 1, beta, y, 1)
   end subroutine gen_matvec

   !> Eigenvalues (ascending) and M-normalized eigenvectors of K phi = lambda M phi.
   subroutine generalized_eigen(k, m, lambda, phi, error)
      real(dp), intent(in) :: k(:, :)                  !! symmetric stiffness
      real(dp), intent(in) :: m(:, :)                  !! symmetric positive definite mass
      real(dp), intent(out) :: lambda(:)               !! eigenvalues w^2, ascending
      real(dp), intent(out) :: phi(:, :)               !! eigenvectors in columns
      type(error_type), allocatable, intent(out) :: error !! LAPACK failure
      real(dp), allocatable :: b(:, :), work(:)
      integer :: n, info, lwork

      n = size(k, 1)
      allocate (b(n, n))
      phi = k
      b = m
      lwork = max(1, 3*n - 1)
      allocate (work(lwork))
      call dsygv(1, 'V', 'U', n, phi, n, b, n, lambda, work, lwork, info)
      if (info /= 0) then
         call fatal_error(error, "eigenvalue solver dsygv failed with info = "//fmt_int(info))
      end if
   end subroutine generalized_eigen

end module fd_linalg
