!> Brent's bracketing root finder (R.P. Brent, Algorithms for Minimization without
!> Derivatives, 1973, ch. 4, "zero"): inverse quadratic and secant steps, safeguarded by
!> bisection, on a bracket whose ends keep opposite signs. The function is an object the
!> caller extends with its own `evaluate` (and the data it needs); an error raised there
!> ends the search and comes back to the caller.
module fd_root_finder
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real
   implicit none
   private

   public :: root_function, brent_root

   !> A function of one real variable whose zero is sought.
   type, abstract :: root_function
   contains
      procedure(evaluate_interface), deferred :: evaluate  !! f(x)
   end type root_function

   abstract interface
      !> f(x); an allocated error stops the search.
      subroutine evaluate_interface(self, x, fx, error)
         import :: root_function, dp, error_type
         class(root_function), intent(inout) :: self          !! the function (and its work)
         real(dp), intent(in) :: x                            !! abscissa
         real(dp), intent(out) :: fx                          !! f(x)
         type(error_type), allocatable, intent(out) :: error  !! failure of the evaluation
      end subroutine evaluate_interface
   end interface

   integer, parameter :: default_max_eval = 200  !! evaluations allowed

contains

   !> A zero of f in the bracket [a, b], given fa = f(a) and fb = f(b) of opposite signs
   !> (or fb = 0); neither end is evaluated here. The search stops when the bracket is
   !> shorter than 2 tol, tol = rtol max(|origin + x|, 1) + atol at the current iterate x
   !> (x is measured from `origin`: for a time step, its start), or when f is exactly 0.
   !> It returns the end of the final bracket that lies on b's side of the sign change
   !> (f there has the sign of fb, or is 0), clamped to [a, b]: the first point at which
   !> the sign of fb is reached, to within the tolerance.
   subroutine brent_root(f, a, fa, b, fb, root, error, origin, rtol, atol, max_eval)
      class(root_function), intent(inout) :: f            !! the function
      real(dp), intent(in) :: a                           !! one end of the bracket
      real(dp), intent(in) :: fa                          !! f(a)
      real(dp), intent(in) :: b                           !! other end of the bracket
      real(dp), intent(in) :: fb                          !! f(b), of opposite sign to fa or 0
      real(dp), intent(out) :: root                       !! the zero found
      type(error_type), allocatable, intent(out) :: error !! no sign change, failed evaluation,
                                                          !! or no convergence
      real(dp), intent(in), optional :: origin            !! x is relative to it (default 0)
      real(dp), intent(in), optional :: rtol              !! relative tolerance (default 2 eps)
      real(dp), intent(in), optional :: atol              !! absolute tolerance (default tiny)
      integer, intent(in), optional :: max_eval           !! evaluations allowed (default 200)
      real(dp) :: xa, ya, xb, yb, xc, yc, d, e, tol, xm, p, q, r, s, x0, rt, at
      integer :: it, nmax
      logical :: converged

      x0 = 0.0_dp
      if (present(origin)) x0 = origin
      rt = 2.0_dp*epsilon(1.0_dp)
      if (present(rtol)) rt = rtol
      at = tiny(1.0_dp)
      if (present(atol)) at = atol
      nmax = default_max_eval
      if (present(max_eval)) nmax = max_eval
      root = b
      if (fb /= 0.0_dp .and. sign(1.0_dp, fa) == sign(1.0_dp, fb) .and. fa /= 0.0_dp) then
         call fatal_error(error, "root finder: no sign change in the bracket ["//trim(fmt_real(a))//", "// &
                          trim(fmt_real(b))//"]: f = "//trim(fmt_real(fa))//", "//trim(fmt_real(fb)))
         return
      end if

      xa = a; ya = fa; xb = b; yb = fb
      xc = xa; yc = ya; d = xb - xa; e = d
      converged = .false.
      do it = 1, nmax + 1
         if (sign(1.0_dp, yb) == sign(1.0_dp, yc) .and. yb /= 0.0_dp) then
            xc = xa; yc = ya; d = xb - xa; e = d
         end if
         if (abs(yc) < abs(yb) .and. yb /= 0.0_dp) then
            xa = xb; xb = xc; xc = xa
            ya = yb; yb = yc; yc = ya
         end if
         tol = rt*max(abs(x0 + xb), 1.0_dp) + at
         xm = 0.5_dp*(xc - xb)
         if (abs(xm) <= tol .or. yb == 0.0_dp) then
            converged = .true.
            exit
         end if
         if (it > nmax) exit
         if (abs(e) >= tol .and. abs(ya) > abs(yb)) then
            s = yb/ya
            if (xa == xc) then
               p = 2.0_dp*xm*s; q = 1.0_dp - s                           ! secant
            else
               q = ya/yc; r = yb/yc                                      ! inverse quadratic
               p = s*(2.0_dp*xm*q*(q - r) - (xb - xa)*(r - 1.0_dp))
               q = (q - 1.0_dp)*(r - 1.0_dp)*(s - 1.0_dp)
            end if
            if (p > 0.0_dp) q = -q
            p = abs(p)
            if (2.0_dp*p < min(3.0_dp*xm*q - abs(tol*q), abs(e*q))) then
               e = d; d = p/q
            else
               d = xm; e = d                                             ! bisection
            end if
         else
            d = xm; e = d
         end if
         xa = xb; ya = yb
         if (abs(d) > tol) then
            xb = xb + d
         else
            xb = xb + sign(tol, xm)
         end if
         call f%evaluate(xb, yb, error)
         if (allocated(error)) then
            root = xb
            return
         end if
      end do
      if (.not. converged) then
         call fatal_error(error, "root finder: no convergence in "//trim(fmt_int(nmax))//" evaluations; bracket ["// &
                          trim(fmt_real(min(xb, xc)))//", "//trim(fmt_real(max(xb, xc)))//"]")
         return
      end if
      ! the end of the final bracket on b's side of the sign change
      if (yb == 0.0_dp .or. sign(1.0_dp, yb) == sign(1.0_dp, fb)) then
         root = xb
      else
         root = xc
      end if
      root = min(max(root, min(a, b)), max(a, b))
   end subroutine brent_root

end module fd_root_finder
