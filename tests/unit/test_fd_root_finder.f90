!> Unit tests of Brent's root finder (fd_root_finder) on functions with known roots:
!> convergence to the tolerance, the side of the sign change it returns, roots at an end
!> of the bracket, and the errors (no sign change, a failing evaluation, no convergence).
module test_fd_root_finder
   use testdrive, only: new_unittest, unittest_type, error_type, check, test_failed
   use fd_kinds, only: dp
   use fd_error, only: fd_error_type => error_type, fatal_error
   use fd_root_finder, only: root_function, brent_root
   implicit none
   private

   public :: collect_root_finder

   integer, parameter :: f_square = 1   !! x^2 - 2
   integer, parameter :: f_kepler = 2   !! cos(x) - x
   integer, parameter :: f_cubic = 3    !! (x - 0.3)^3, a triple root
   integer, parameter :: f_step = 4     !! -1 below 0.4, +1 from there: no zero, a jump
   integer, parameter :: f_linear = 5   !! x - 0.3

   !> A test function that counts its evaluations, and may fail at the n-th.
   type, extends(root_function) :: test_function
      integer :: which = f_square
      integer :: evaluations = 0
      integer :: fail_at = -1          !! evaluation that raises an error (-1: none)
   contains
      procedure :: evaluate
   end type test_function

contains

   subroutine collect_root_finder(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("known roots to the tolerance", test_known_roots), &
                  new_unittest("multiple root and a jump", test_hard_functions), &
                  new_unittest("end on b's side of the sign change", test_bracket_side), &
                  new_unittest("loose tolerance, fewer evaluations", test_tolerance), &
                  new_unittest("tolerance relative to the origin", test_origin), &
                  new_unittest("root at an end of the bracket", test_root_at_end), &
                  new_unittest("no sign change is an error", test_no_sign_change), &
                  new_unittest("a failing evaluation is an error", test_failing_function), &
                  new_unittest("no convergence is an error", test_no_convergence) &
                  ]
   end subroutine collect_root_finder

   subroutine evaluate(self, x, fx, error)
      class(test_function), intent(inout) :: self
      real(dp), intent(in) :: x
      real(dp), intent(out) :: fx
      type(fd_error_type), allocatable, intent(out) :: error

      self%evaluations = self%evaluations + 1
      fx = 0.0_dp
      if (self%evaluations == self%fail_at) then
         call fatal_error(error, "test function: evaluation failed")
         return
      end if
      select case (self%which)
      case (f_square)
         fx = x*x - 2.0_dp
      case (f_kepler)
         fx = cos(x) - x
      case (f_cubic)
         fx = (x - 0.3_dp)**3
      case (f_step)
         fx = merge(-1.0_dp, 1.0_dp, x < 0.4_dp)
      case (f_linear)
         fx = x - 0.3_dp
      end select
   end subroutine evaluate

   !> f(x) of the test function without counting.
   real(dp) function value_of(which, x) result(fx)
      integer, intent(in) :: which
      real(dp), intent(in) :: x
      type(test_function) :: f
      type(fd_error_type), allocatable :: err

      f%which = which
      call f%evaluate(x, fx, err)
   end function value_of

   !> sqrt(2) and the Dottie number cos(x) = x, to 2 eps relative (the default tolerance
   !> is 2 eps max(|x|, 1) + tiny: the bracket ends within two of those).
   subroutine test_known_roots(error)
      type(error_type), allocatable, intent(out) :: error
      type(test_function) :: f
      type(fd_error_type), allocatable :: err
      real(dp) :: root

      f%which = f_square
      call brent_root(f, 0.0_dp, -2.0_dp, 2.0_dp, 2.0_dp, root, err)
      call check(error, .not. allocated(err), "sqrt(2): unexpected error")
      if (allocated(error)) return
      call check(error, root, sqrt(2.0_dp), thr=4.0_dp*epsilon(1.0_dp)*sqrt(2.0_dp))
      if (allocated(error)) return
      ! superlinear convergence: far fewer evaluations than bisection's 52
      call check(error, f%evaluations <= 12, "sqrt(2) took too many evaluations")
      if (allocated(error)) return

      f = test_function(which=f_kepler)
      call brent_root(f, 0.0_dp, 1.0_dp, 1.0_dp, cos(1.0_dp) - 1.0_dp, root, err)
      call check(error, .not. allocated(err), "cos(x) = x: unexpected error")
      if (allocated(error)) return
      call check(error, root, 0.73908513321516064_dp, thr=4.0_dp*epsilon(1.0_dp))
   end subroutine test_known_roots

   !> A triple root (slow for interpolation: the bisection safeguard) and a jump with no
   !> zero (the sign change itself is found, to the tolerance).
   subroutine test_hard_functions(error)
      type(error_type), allocatable, intent(out) :: error
      type(test_function) :: f
      type(fd_error_type), allocatable :: err
      real(dp) :: root

      f%which = f_cubic
      call brent_root(f, 0.0_dp, value_of(f_cubic, 0.0_dp), 1.0_dp, value_of(f_cubic, 1.0_dp), root, err)
      call check(error, .not. allocated(err), "triple root: unexpected error")
      if (allocated(error)) return
      ! (x - 0.3)^3 underflows to 0 within about 1e-103 of the root; the search stops at f = 0
      ! or when the bracket is within the tolerance
      call check(error, root, 0.3_dp, thr=4.0_dp*epsilon(1.0_dp))
      if (allocated(error)) return

      f = test_function(which=f_step)
      call brent_root(f, 0.0_dp, -1.0_dp, 1.0_dp, 1.0_dp, root, err)
      call check(error, .not. allocated(err), "jump: unexpected error")
      if (allocated(error)) return
      call check(error, root, 0.4_dp, thr=4.0_dp*epsilon(1.0_dp))
      if (allocated(error)) return
      ! the end returned is on b's side: f(root) has the sign of f(b) = +1
      call check(error, root >= 0.4_dp, "jump: the root returned is before the jump")
   end subroutine test_hard_functions

   !> The end returned lies on b's side of the sign change, for either orientation of the
   !> bracket and either sign of f(b): stepping to it, the sign of f(b) has been reached.
   subroutine test_bracket_side(error)
      type(error_type), allocatable, intent(out) :: error
      type(test_function) :: f
      type(fd_error_type), allocatable :: err
      real(dp) :: root, fr

      f%which = f_linear
      ! increasing f, b on the right: f(root) >= 0
      call brent_root(f, 0.0_dp, -0.3_dp, 1.0_dp, 0.7_dp, root, err)
      if (allocated(err)) then
         call test_failed(error, err%message); return
      end if
      fr = value_of(f_linear, root)
      call check(error, fr >= 0.0_dp .and. abs(root - 0.3_dp) <= 4.0_dp*epsilon(1.0_dp), &
                 "b = 1: root not on b's side or not converged")
      if (allocated(error)) return
      ! the same bracket given from the other end: f(root) <= 0
      call brent_root(f, 1.0_dp, 0.7_dp, 0.0_dp, -0.3_dp, root, err)
      if (allocated(err)) then
         call test_failed(error, err%message); return
      end if
      fr = value_of(f_linear, root)
      call check(error, fr <= 0.0_dp .and. abs(root - 0.3_dp) <= 4.0_dp*epsilon(1.0_dp), &
                 "b = 0: root not on b's side or not converged")
      if (allocated(error)) return
      ! the event convention of the exact technique: f(a) > 0 given (not evaluated), f(b) <= 0
      f = test_function(which=f_linear)
      call brent_root(f, 0.5_dp, 1.0_dp, 0.2_dp, value_of(f_linear, 0.2_dp), root, err)
      if (allocated(err)) then
         call test_failed(error, err%message); return
      end if
      call check(error, value_of(f_linear, root) <= 0.0_dp .and. root <= 0.3_dp .and. root >= 0.2_dp, &
                 "event convention: the root is where f first reaches <= 0")
   end subroutine test_bracket_side

   !> A loose relative tolerance stops earlier, within that tolerance.
   subroutine test_tolerance(error)
      type(error_type), allocatable, intent(out) :: error
      type(test_function) :: f, g
      type(fd_error_type), allocatable :: err
      real(dp) :: root, tight

      f%which = f_kepler
      call brent_root(f, 0.0_dp, 1.0_dp, 1.0_dp, cos(1.0_dp) - 1.0_dp, tight, err)
      g%which = f_kepler
      call brent_root(g, 0.0_dp, 1.0_dp, 1.0_dp, cos(1.0_dp) - 1.0_dp, root, err, rtol=1.0e-4_dp, atol=0.0_dp)
      if (allocated(err)) then
         call test_failed(error, err%message); return
      end if
      ! converged: the bracket (of length <= 2 tol) holds the root, tol = 1e-4 max(|x|, 1)
      call check(error, abs(root - 0.73908513321516064_dp) <= 2.0e-4_dp, "loose tolerance: not within 2 tol")
      if (allocated(error)) return
      call check(error, g%evaluations < f%evaluations, "a loose tolerance should take fewer evaluations")
   end subroutine test_tolerance

   !> The tolerance is relative to |origin + x|: a time step far from t = 0 resolves its
   !> zero to the precision of the absolute time, not of the step.
   subroutine test_origin(error)
      type(error_type), allocatable, intent(out) :: error
      type(test_function) :: f, g
      type(fd_error_type), allocatable :: err
      real(dp) :: near, far

      f%which = f_linear
      call brent_root(f, 0.0_dp, -0.3_dp, 1.0_dp, 0.7_dp, near, err)
      g%which = f_linear
      call brent_root(g, 0.0_dp, -0.3_dp, 1.0_dp, 0.7_dp, far, err, origin=1.0e6_dp)
      if (allocated(err)) then
         call test_failed(error, err%message); return
      end if
      ! at t = 1e6 the tolerance is 2 eps 1e6 ~ 4.4e-10
      call check(error, abs(far - 0.3_dp) <= 2.0_dp*2.0_dp*epsilon(1.0_dp)*1.0e6_dp, "origin: not converged")
      if (allocated(error)) return
      call check(error, g%evaluations <= f%evaluations, "origin: a larger tolerance took more evaluations")
   end subroutine test_origin

   !> f(b) = 0: b, with no evaluation; f(a) = 0: a.
   subroutine test_root_at_end(error)
      type(error_type), allocatable, intent(out) :: error
      type(test_function) :: f
      type(fd_error_type), allocatable :: err
      real(dp) :: root

      f%which = f_linear
      call brent_root(f, 0.0_dp, -0.3_dp, 0.3_dp, 0.0_dp, root, err)
      call check(error, .not. allocated(err), "root at b: unexpected error")
      if (allocated(error)) return
      call check(error, root == 0.3_dp .and. f%evaluations == 0, "root at b: b itself, without evaluating")
      if (allocated(error)) return
      f = test_function(which=f_linear)
      call brent_root(f, 0.3_dp, 0.0_dp, 1.0_dp, 0.7_dp, root, err)
      call check(error, .not. allocated(err), "root at a: unexpected error")
      if (allocated(error)) return
      call check(error, root == 0.3_dp .and. f%evaluations == 0, "root at a: a itself, without evaluating")
   end subroutine test_root_at_end

   subroutine test_no_sign_change(error)
      type(error_type), allocatable, intent(out) :: error
      type(test_function) :: f
      type(fd_error_type), allocatable :: err
      real(dp) :: root

      f%which = f_square
      call brent_root(f, 2.0_dp, 2.0_dp, 3.0_dp, 7.0_dp, root, err)
      call check(error, allocated(err), "no sign change: no error")
      if (allocated(error)) return
      call check(error, index(err%message, 'no sign change') > 0, "no sign change: message "//err%message)
      if (allocated(error)) return
      call check(error, f%evaluations == 0, "no sign change: evaluated")
   end subroutine test_no_sign_change

   !> An error raised by the function at its third evaluation comes back as it is.
   subroutine test_failing_function(error)
      type(error_type), allocatable, intent(out) :: error
      type(test_function) :: f
      type(fd_error_type), allocatable :: err
      real(dp) :: root

      f = test_function(which=f_square, fail_at=3)
      call brent_root(f, 0.0_dp, -2.0_dp, 2.0_dp, 2.0_dp, root, err)
      call check(error, allocated(err), "failing evaluation: no error")
      if (allocated(error)) return
      call check(error, err%message, "test function: evaluation failed")
      if (allocated(error)) return
      call check(error, f%evaluations == 3, "failing evaluation: the search went on after the error")
   end subroutine test_failing_function

   subroutine test_no_convergence(error)
      type(error_type), allocatable, intent(out) :: error
      type(test_function) :: f
      type(fd_error_type), allocatable :: err
      real(dp) :: root

      f%which = f_kepler
      call brent_root(f, 0.0_dp, 1.0_dp, 1.0_dp, cos(1.0_dp) - 1.0_dp, root, err, max_eval=2)
      call check(error, allocated(err), "2 evaluations cannot converge: no error")
      if (allocated(error)) return
      call check(error, index(err%message, 'no convergence in 2 evaluations') > 0, "message: "//err%message)
      if (allocated(error)) return
      call check(error, f%evaluations == 2, "more evaluations than allowed")
   end subroutine test_no_convergence

end module test_fd_root_finder
