!> Interfaces of the LAPACK and BLAS routines the library calls, in one place (the reference
!> LAPACK argument lists; Debian's liblapack-dev and libblas-dev provide them).
module fd_lapack
   use fd_kinds, only: dp
   implicit none
   private

   public :: dgelss, dgemv, dgesv, dgetrf, dgetrs, dpbtf2, dpbtrf, dpbtrs, dpotf2, dpotrf, dpotrs, dpttrf, dpttrs, &
             dsbevx, dsbgvx, dsbmv, dsterf, dsyevr, dsygv, dsymv, dsyrk, dtrsv

   !> The BLAS products y := alpha A x + beta y of a matrix given by one option and two sizes:
   !> dgemv (opt = trans; n1, n2 = m, n: A general m x n) and dsbmv (opt = uplo; n1, n2 = n, k:
   !> A symmetric, k superdiagonals in band storage).
   abstract interface
      subroutine blas_matvec(opt, n1, n2, alpha, a, lda, x, incx, beta, y, incy)
         import :: dp
         character(len=1), intent(in) :: opt
         integer, intent(in) :: n1, n2, lda, incx, incy
         real(dp), intent(in) :: alpha, beta
         real(dp), intent(in) :: a(lda, *), x(*)
         real(dp), intent(inout) :: y(*)
      end subroutine blas_matvec
   end interface

   interface
      subroutine dgelss(m, n, nrhs, a, lda, b, ldb, s, rcond, rank, work, lwork, info)
         import :: dp
         integer, intent(in) :: m, n, nrhs, lda, ldb, lwork
         real(dp), intent(inout) :: a(lda, *), b(ldb, *)
         real(dp), intent(out) :: s(*), work(*)
         real(dp), intent(in) :: rcond
         integer, intent(out) :: rank, info
      end subroutine dgelss
      subroutine dgesv(n, nrhs, a, lda, ipiv, b, ldb, info)
         import :: dp
         integer, intent(in) :: n, nrhs, lda, ldb
         real(dp), intent(inout) :: a(lda, *), b(ldb, *)
         integer, intent(out) :: ipiv(*), info
      end subroutine dgesv
      subroutine dgetrf(m, n, a, lda, ipiv, info)
         import :: dp
         integer, intent(in) :: m, n, lda
         real(dp), intent(inout) :: a(lda, *)
         integer, intent(out) :: ipiv(*), info
      end subroutine dgetrf
      subroutine dgetrs(trans, n, nrhs, a, lda, ipiv, b, ldb, info)
         import :: dp
         character(len=1), intent(in) :: trans
         integer, intent(in) :: n, nrhs, lda, ldb, ipiv(*)
         real(dp), intent(in) :: a(lda, *)
         real(dp), intent(inout) :: b(ldb, *)
         integer, intent(out) :: info
      end subroutine dgetrs
      subroutine dpbtrf(uplo, n, kd, ab, ldab, info)
         import :: dp
         character(len=1), intent(in) :: uplo
         integer, intent(in) :: n, kd, ldab
         real(dp), intent(inout) :: ab(ldab, *)
         integer, intent(out) :: info
      end subroutine dpbtrf
      subroutine dpbtrs(uplo, n, kd, nrhs, ab, ldab, b, ldb, info)
         import :: dp
         character(len=1), intent(in) :: uplo
         integer, intent(in) :: n, kd, nrhs, ldab, ldb
         real(dp), intent(in) :: ab(ldab, *)
         real(dp), intent(inout) :: b(ldb, *)
         integer, intent(out) :: info
      end subroutine dpbtrs
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
      subroutine dpttrf(n, d, e, info)
         import :: dp
         integer, intent(in) :: n
         real(dp), intent(inout) :: d(*), e(*)
         integer, intent(out) :: info
      end subroutine dpttrf
      subroutine dpttrs(n, nrhs, d, e, b, ldb, info)
         import :: dp
         integer, intent(in) :: n, nrhs, ldb
         real(dp), intent(in) :: d(*), e(*)
         real(dp), intent(inout) :: b(ldb, *)
         integer, intent(out) :: info
      end subroutine dpttrs
      subroutine dsbevx(jobz, range, uplo, n, kd, ab, ldab, q, ldq, vl, vu, il, iu, abstol, m, w, z, &
                        ldz, work, iwork, ifail, info)
         import :: dp
         character(len=1), intent(in) :: jobz, range, uplo
         integer, intent(in) :: n, kd, ldab, ldq, il, iu, ldz
         real(dp), intent(inout) :: ab(ldab, *)
         real(dp), intent(in) :: vl, vu, abstol
         integer, intent(out) :: m, iwork(*), ifail(*), info
         real(dp), intent(out) :: q(ldq, *), w(*), z(ldz, *), work(*)
      end subroutine dsbevx
      subroutine dsbgvx(jobz, range, uplo, n, ka, kb, ab, ldab, bb, ldbb, q, ldq, vl, vu, il, iu, &
                        abstol, m, w, z, ldz, work, iwork, ifail, info)
         import :: dp
         character(len=1), intent(in) :: jobz, range, uplo
         integer, intent(in) :: n, ka, kb, ldab, ldbb, ldq, il, iu, ldz
         real(dp), intent(inout) :: ab(ldab, *), bb(ldbb, *)
         real(dp), intent(out) :: q(ldq, *), z(ldz, *), w(*), work(*)
         real(dp), intent(in) :: vl, vu, abstol
         integer, intent(out) :: m, iwork(*), ifail(*), info
      end subroutine dsbgvx
      subroutine dsyevr(jobz, range, uplo, n, a, lda, vl, vu, il, iu, abstol, m, w, z, ldz, isuppz, &
                        work, lwork, iwork, liwork, info)
         import :: dp
         character(len=1), intent(in) :: jobz, range, uplo
         integer, intent(in) :: n, lda, il, iu, ldz, lwork, liwork
         real(dp), intent(inout) :: a(lda, *)
         real(dp), intent(in) :: vl, vu, abstol
         integer, intent(out) :: m, isuppz(*), iwork(*), info
         real(dp), intent(out) :: w(*), z(ldz, *), work(*)
      end subroutine dsyevr
      subroutine dsygv(itype, jobz, uplo, n, a, lda, b, ldb, w, work, lwork, info)
         import :: dp
         integer, intent(in) :: itype, n, lda, ldb, lwork
         character(len=1), intent(in) :: jobz, uplo
         real(dp), intent(inout) :: a(lda, *), b(ldb, *)
         real(dp), intent(out) :: w(*), work(*)
         integer, intent(out) :: info
      end subroutine dsygv
      subroutine dsymv(uplo, n, alpha, a, lda, x, incx, beta, y, incy)
         import :: dp
         character(len=1), intent(in) :: uplo
         integer, intent(in) :: n, lda, incx, incy
         real(dp), intent(in) :: alpha, beta
         real(dp), intent(in) :: a(lda, *), x(*)
         real(dp), intent(inout) :: y(*)
      end subroutine dsymv
      subroutine dsyrk(uplo, trans, n, k, alpha, a, lda, beta, c, ldc)
         import :: dp
         character(len=1), intent(in) :: uplo, trans
         integer, intent(in) :: n, k, lda, ldc
         real(dp), intent(in) :: alpha, beta
         real(dp), intent(in) :: a(lda, *)
         real(dp), intent(inout) :: c(ldc, *)
      end subroutine dsyrk
      subroutine dtrsv(uplo, trans, diag, n, a, lda, x, incx)
         import :: dp
         character(len=1), intent(in) :: uplo, trans, diag
         integer, intent(in) :: n, lda, incx
         real(dp), intent(in) :: a(lda, *)
         real(dp), intent(inout) :: x(*)
      end subroutine dtrsv
   end interface

   procedure(blas_matvec) :: dgemv, dsbmv
   !> The unblocked Cholesky factorizations take the blocked ones' arguments.
   procedure(dpbtrf) :: dpbtf2
   procedure(dpotrf) :: dpotf2
   !> Every eigenvalue of a symmetric tridiagonal matrix (ascending, in d): the tridiagonal
   !> matrix given as dpttrf takes it (n, d, e, info).
   procedure(dpttrf) :: dsterf

end module fd_lapack
