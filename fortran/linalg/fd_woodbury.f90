!> A symmetric low-rank term U diag(d) U' (U n x r, d >= 0) added to a factored effective
!> stiffness A (fd_banded's spd_system), solved without forming an n x n matrix by the
!> Woodbury identity. With V = U diag(sqrt(c d)) (c the term's coefficient in the system):
!>
!>   (A + V V')^-1 = A^-1 - W S^-1 W',   W = A^-1 V,   S = I + V' W (r x r, SPD),
!>
!> so a solve is A's solve followed by x := x - W S^-1 (V' x): O(n r) besides A's solve.
!> W and the Cholesky factor of S are computed once per factorization of A (r solves with
!> A, O(n r^2) for S) and again whenever A's factor changes. Modal damping C = M Phi
!> diag(2 xi w / m) Phi' M is such a term (docs/theory.md, "Modal damping").
module fd_woodbury
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, stat_no_memory
   use fd_lapack, only: dpotrf, dpotrs, dgemv
   use fd_banded, only: spd_system, spd_solve
   implicit none
   private

   public :: woodbury_type, lowrank_matvec, lowrank_form, woodbury_setup, woodbury_factor
   public :: woodbury_correct

   !> The Woodbury factors of A + c U diag(d) U' for one A (one step size).
   type :: woodbury_type
      integer :: r = 0
      real(dp) :: c = 0.0_dp                !! the term's coefficient in the system
      real(dp), allocatable :: s(:)         !! sqrt(c d): V = U diag(s)
      real(dp), allocatable :: w(:, :)      !! (n, r) A^-1 V
      real(dp), allocatable :: cap(:, :)    !! (r, r) Cholesky factor of I + V' W
      real(dp), allocatable :: t(:)         !! (r) work
   end type woodbury_type

contains

   !> y = y + alpha U diag(d) U' x: O(n r), two BLAS products.
   subroutine lowrank_matvec(u, d, x, y, alpha)
      real(dp), intent(in), contiguous :: u(:, :)  !! U, n x r
      real(dp), intent(in) :: d(:)                 !! its weights, size r
      real(dp), intent(in), contiguous :: x(:)     !! vector, size n
      real(dp), intent(inout), contiguous :: y(:)  !! result, size n
      real(dp), intent(in) :: alpha          !! factor
      real(dp) :: t(size(d))
      integer :: n, r

      n = size(u, 1); r = size(d)
      if (r == 0 .or. n == 0) return
      call dgemv('T', n, r, 1.0_dp, u, n, x, 1, 0.0_dp, t, 1)
      t = alpha*d*t
      call dgemv('N', n, r, 1.0_dp, u, n, t, 1, 1.0_dp, y, 1)
   end subroutine lowrank_matvec

   !> x' U diag(d) U' y: the term's bilinear form, O(n r).
   pure real(dp) function lowrank_form(u, d, x, y) result(e)
      real(dp), intent(in) :: u(:, :)        !! U, n x r
      real(dp), intent(in) :: d(:)           !! its weights, size r
      real(dp), intent(in) :: x(:), y(:)     !! vectors, size n
      integer :: k

      e = 0.0_dp
      do k = 1, size(d)
         e = e + d(k)*dot_product(u(:, k), x)*dot_product(u(:, k), y)
      end do
   end function lowrank_form

   !> Allocate the factors of A + c U diag(d) U' (nothing allocates afterwards).
   subroutine woodbury_setup(wb, u, d, c, error)
      type(woodbury_type), intent(out) :: wb  !! the factors, to be computed by woodbury_factor
      real(dp), intent(in) :: u(:, :)         !! U, n x r
      real(dp), intent(in) :: d(:)            !! its weights, size r, >= 0
      real(dp), intent(in) :: c               !! its coefficient, >= 0
      type(error_type), allocatable, intent(out) :: error !! bad coefficient, no memory
      integer :: stat

      if (.not. (c >= 0.0_dp .and. ieee_is_finite(c))) then
         call fatal_error(error, "woodbury_setup: the coefficient of the low-rank term is not a finite value >= 0")
         return
      end if
      if (any(d < 0.0_dp) .or. size(u, 2) /= size(d)) then
         call fatal_error(error, "woodbury_setup: a weight of the low-rank term is negative, or their number is not U's")
         return
      end if
      wb%r = size(d)
      wb%c = c
      allocate (wb%s(wb%r), wb%w(size(u, 1), wb%r), wb%cap(wb%r, wb%r), wb%t(wb%r), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the low-rank term ("//trim(fmt_int(size(u, 1)))//" x "// &
                          trim(fmt_int(wb%r))//")", stat_no_memory)
         return
      end if
      wb%s = sqrt(c*d)
   end subroutine woodbury_setup

   !> W = A^-1 V and the Cholesky factor of S = I + V' W, for A's current factor (sys).
   subroutine woodbury_factor(wb, u, sys, error)
      type(woodbury_type), intent(inout) :: wb   !! the factors (set up)
      real(dp), intent(in) :: u(:, :)            !! U, n x r
      type(spd_system), intent(inout) :: sys     !! A, factored
      type(error_type), allocatable, intent(out) :: error !! A not factored, S not positive definite
      integer :: i, j, info

      if (wb%r == 0) return
      do j = 1, wb%r
         wb%w(:, j) = wb%s(j)*u(:, j)
         call spd_solve(sys, wb%w(:, j), error)
         if (allocated(error)) return
      end do
      do j = 1, wb%r
         do i = 1, j
            wb%cap(i, j) = wb%s(i)*dot_product(u(:, i), wb%w(:, j))
         end do
         wb%cap(j, j) = wb%cap(j, j) + 1.0_dp
      end do
      call dpotrf('U', wb%r, wb%cap, wb%r, info)
      if (info /= 0) then
         call fatal_error(error, "woodbury_factor: I + V' A^-1 V is not positive definite (column "// &
                          trim(fmt_int(info))//")")
      end if
   end subroutine woodbury_factor

   !> x := x - W S^-1 (V' x): with x = A^-1 b on entry, (A + V V')^-1 b on exit.
   subroutine woodbury_correct(wb, u, x)
      type(woodbury_type), intent(inout) :: wb   !! the factors (computed)
      real(dp), intent(in), contiguous :: u(:, :)   !! U, n x r
      real(dp), intent(inout), contiguous :: x(:)   !! A^-1 b on entry, the solution on exit
      integer :: n, info

      if (wb%r == 0) return
      n = size(u, 1)
      call dgemv('T', n, wb%r, 1.0_dp, u, n, x, 1, 0.0_dp, wb%t, 1)
      wb%t = wb%s*wb%t
      call dpotrs('U', wb%r, 1, wb%cap, wb%r, wb%t, wb%r, info)
      call dgemv('N', n, wb%r, -1.0_dp, wb%w, n, wb%t, 1, 1.0_dp, x, 1)
   end subroutine woodbury_correct

end module fd_woodbury
