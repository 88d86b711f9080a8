!> Thin wrappers over the LAPACK and BLAS routines frictiondyn uses: Cholesky
!> factorization and solve of the effective stiffness, symmetric matrix-vector products,
!> and the generalized symmetric eigenproblem K phi = w^2 M phi.
module fd_linalg
   use fd_kinds, only: dp
   use fd_lapack, only: dgelss, dgemv, dgesv, dpotrf, dpotrs, dsbevx, dsyevr, dsygv, dsymv
   use fd_error, only: error_type, fatal_error, fmt_int, stat_no_memory
   use, intrinsic :: ieee_exceptions, only: ieee_set_halting_mode, ieee_get_halting_mode, ieee_support_halting, &
                                            ieee_set_flag, ieee_flag_type, ieee_invalid, ieee_divide_by_zero, &
                                            ieee_overflow
   implicit none
   private

   public :: cholesky_factor, cholesky_solve, sym_matvec, gen_matvec, generalized_eigen
   public :: lu_solve, least_squares, least_squares_work, lowest_eigen, lowest_eigen_band

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

   !> Solve A X = B by LU factorization (A and B overwritten; B becomes X).
   subroutine lu_solve(a, b, ipiv, info)
      real(dp), intent(inout) :: a(:, :)   !! square matrix, its LU factors on exit
      real(dp), intent(inout) :: b(:, :)   !! right-hand sides, the solution on exit
      integer, intent(out) :: ipiv(:)      !! pivots
      integer, intent(out) :: info         !! 0, or > 0 for a singular A

      call dgesv(size(a, 1), size(b, 2), a, size(a, 1), ipiv, b, size(b, 1), info)
   end subroutine lu_solve

   !> Work length for least_squares with an m x n matrix.
   pure integer function least_squares_work(m, n) result(lwork)
      integer, intent(in) :: m   !! rows
      integer, intent(in) :: n   !! columns

      lwork = 3*min(m, n) + max(2*min(m, n), max(m, n), 1) + 4*(m + n) + 64
   end function least_squares_work

   !> Minimum-norm least-squares solution of A x = b by the SVD (LAPACK dgelss): b(1:n)
   !> holds x on exit; b needs max(m, n) rows. A is overwritten.
   subroutine least_squares(a, b, sv, work, info)
      real(dp), intent(inout) :: a(:, :)   !! m x n matrix
      real(dp), intent(inout) :: b(:, :)   !! right-hand side(s), max(m, n) rows
      real(dp), intent(out) :: sv(:)       !! singular values, min(m, n)
      real(dp), intent(inout) :: work(:)   !! work, least_squares_work(m, n)
      integer, intent(out) :: info         !! 0, or the LAPACK failure
      integer :: rank

      call dgelss(size(a, 1), size(a, 2), size(b, 2), a, size(a, 1), b, size(b, 1), sv, -1.0_dp, rank, &
                  work, size(work), info)
   end subroutine least_squares

   !> The k lowest eigenvalues (ascending) and orthonormal eigenvectors of a symmetric
   !> matrix (LAPACK dsyevr: the tridiagonal reduction, then only the k pairs asked for).
   subroutine lowest_eigen(a, k, lambda, vec, error)
      real(dp), intent(in) :: a(:, :)                  !! symmetric matrix (n x n)
      integer, intent(in) :: k                         !! pairs wanted, 1..n
      real(dp), intent(out) :: lambda(:)               !! (k) eigenvalues, ascending
      real(dp), intent(out) :: vec(:, :)               !! (n, k) eigenvectors in columns
      type(error_type), allocatable, intent(out) :: error !! LAPACK failure
      type(ieee_flag_type), parameter :: quiet(3) = [ieee_invalid, ieee_divide_by_zero, ieee_overflow]
      logical :: halting(3)
      integer :: e

      ! dsyevr's MRRR algorithm (dstemr) computes with infinities and NaNs on purpose (it
      ! tests LAPACK's ieeeok): a build that traps them (-ffpe-trap, tools/test_checked.sh)
      ! must not stop inside LAPACK. The halting modes are saved, switched off for the solve,
      ! the flags LAPACK raised cleared, and the modes set back as they were (gfortran does
      ! not restore them on return here, as Fortran 2008's 14.3 would: without this, every
      ! run of the checked build stopped trapping at its first eigenproblem).
      call ieee_get_halting_mode(quiet, halting)
      do e = 1, size(quiet)
         if (ieee_support_halting(quiet(e))) call ieee_set_halting_mode(quiet(e), .false.)
      end do
      call solve()
      call ieee_set_flag(quiet, .false.)
      do e = 1, size(quiet)
         if (ieee_support_halting(quiet(e))) call ieee_set_halting_mode(quiet(e), halting(e))
      end do

   contains

      subroutine solve()
         real(dp), allocatable :: b(:, :), w(:), work(:)
         integer, allocatable :: iwork(:), isuppz(:)
         real(dp) :: query(1)
         integer :: n, m, info, iquery(1), stat

         n = size(a, 1)
         allocate (b(n, n), w(n), isuppz(2*max(1, k)), stat=stat)
         if (stat /= 0) then
            call no_memory(n); return
         end if
         b = a
         call dsyevr('V', 'I', 'U', n, b, n, 0.0_dp, 0.0_dp, 1, k, 0.0_dp, m, w, vec, n, isuppz, &
                     query, -1, iquery, -1, info)
         allocate (work(max(1, int(query(1)))), iwork(max(1, iquery(1))), stat=stat)
         if (stat /= 0) then
            call no_memory(n); return
         end if
         call dsyevr('V', 'I', 'U', n, b, n, 0.0_dp, 0.0_dp, 1, k, 0.0_dp, m, w, vec, n, isuppz, &
                     work, size(work), iwork, size(iwork), info)
         if (info /= 0 .or. m /= k) then
            call fatal_error(error, "eigenvalue solver dsyevr failed with info = "//trim(fmt_int(info)))
            return
         end if
         if (any(w(1:k) /= w(1:k)) .or. any(abs(w(1:k)) > huge(1.0_dp))) then
            call fatal_error(error, "eigenvalue solver dsyevr returned values that are not finite")
            return
         end if
         lambda = w(1:k)
      end subroutine solve

      subroutine no_memory(n)
         integer, intent(in) :: n
         call fatal_error(error, "not enough memory for the eigenproblem of "//trim(fmt_int(n))//" unknowns", &
                          stat_no_memory)
      end subroutine no_memory
   end subroutine lowest_eigen

   !> The k lowest eigenvalues (ascending) and orthonormal eigenvectors of a symmetric band
   !> matrix in LAPACK's upper band storage, ab(kd + 1 + i - j, j) = a(i, j) (dsbevx: the
   !> band reduction costs O(n kd^2), not O(n^3)).
   subroutine lowest_eigen_band(ab, k, lambda, vec, error)
      real(dp), intent(in) :: ab(:, :)                 !! (kd + 1, n) upper band storage
      integer, intent(in) :: k                         !! pairs wanted, 1..n
      real(dp), intent(out) :: lambda(:)               !! (k) eigenvalues, ascending
      real(dp), intent(out) :: vec(:, :)               !! (n, k) eigenvectors in columns
      type(error_type), allocatable, intent(out) :: error !! LAPACK failure
      real(dp), allocatable :: b(:, :), q(:, :), w(:), work(:)
      integer, allocatable :: iwork(:), ifail(:)
      integer :: n, kd, m, info, stat

      kd = size(ab, 1) - 1
      n = size(ab, 2)
      allocate (b(kd + 1, n), q(n, n), w(n), work(7*n), iwork(5*n), ifail(n), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the band eigenproblem of "//trim(fmt_int(n))//" unknowns", &
                          stat_no_memory)
         return
      end if
      b = ab
      call dsbevx('V', 'I', 'U', n, kd, b, kd + 1, q, n, 0.0_dp, 0.0_dp, 1, k, 0.0_dp, m, w, vec, n, &
                  work, iwork, ifail, info)
      if (info /= 0 .or. m /= k) then
         call fatal_error(error, "eigenvalue solver dsbevx failed with info = "//trim(fmt_int(info)))
         return
      end if
      lambda = w(1:k)
   end subroutine lowest_eigen_band

   !> Eigenvalues (ascending) and M-normalized eigenvectors of K phi = lambda M phi.
   subroutine generalized_eigen(k, m, lambda, phi, error)
      real(dp), intent(in) :: k(:, :)                  !! symmetric stiffness
      real(dp), intent(in) :: m(:, :)                  !! symmetric positive definite mass
      real(dp), intent(out) :: lambda(:)               !! eigenvalues w^2, ascending
      real(dp), intent(out) :: phi(:, :)               !! eigenvectors in columns
      type(error_type), allocatable, intent(out) :: error !! LAPACK failure
      real(dp), allocatable :: b(:, :), work(:)
      integer :: n, info, lwork, stat

      n = size(k, 1)
      lwork = max(1, 3*n - 1)
      allocate (b(n, n), work(lwork), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for an eigenproblem of order "//trim(fmt_int(n)), stat_no_memory)
         return
      end if
      phi = k
      b = m
      call dsygv(1, 'V', 'U', n, phi, n, b, n, lambda, work, lwork, info)
      if (info /= 0) then
         call fatal_error(error, "eigenvalue solver dsygv failed with info = "//trim(fmt_int(info)))
      end if
   end subroutine generalized_eigen

end module fd_linalg
