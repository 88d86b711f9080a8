!> Checks shared by the unit suites: real values and matrices against expected ones with an
!> explicit tolerance, failing with both values and the error in the message (test-drive's
!> relative check reports the difference in whole percent, which hides 1e-14).
!> With FD_UNIT_REPORT set in the environment every check prints its measured error, the
!> numbers the tolerances were set from: FD_UNIT_REPORT=1 build/unit/tests/unit/tester expm
module test_fd_helpers
   use, intrinsic :: iso_fortran_env, only: output_unit
   use testdrive, only: error_type, test_failed
   use fd_kinds, only: dp
   use fd_model, only: model_type
   use fd_kinematics, only: set_pair_directions
   implicit none
   private

   public :: check_close, check_matrix, pairs_of

contains

   !> |actual - expected| <= tol |expected| (rel, the default) or <= tol (absolute).
   subroutine check_close(error, actual, expected, tol, what, absolute)
      type(error_type), allocatable, intent(out) :: error !! set on mismatch
      real(dp), intent(in) :: actual                      !! computed value
      real(dp), intent(in) :: expected                    !! closed form
      real(dp), intent(in) :: tol                         !! tolerance
      character(len=*), intent(in) :: what                !! what is compared
      logical, intent(in), optional :: absolute           !! tol is absolute
      real(dp) :: err
      character(len=120) :: line
      logical :: abs_

      abs_ = .false.
      if (present(absolute)) abs_ = absolute
      err = abs(actual - expected)
      if (.not. abs_ .and. expected /= 0.0_dp) err = err/abs(expected)
      call report(what, err, tol)
      if (.not. (err <= tol)) then
         write (line, '(a,es24.16,a,es24.16,a,es9.2,a,es9.2)') 'got', actual, ' expected', expected, &
            ' error', err, ' > ', tol
         call test_failed(error, what, trim(line))
      end if
   end subroutine check_close

   !> max |a - b| <= tol max |b|: matrices equal to a tolerance relative to their size.
   subroutine check_matrix(error, a, b, tol, what)
      type(error_type), allocatable, intent(out) :: error !! set on mismatch
      real(dp), intent(in) :: a(:, :)                     !! computed matrix
      real(dp), intent(in) :: b(:, :)                     !! expected matrix
      real(dp), intent(in) :: tol                         !! relative tolerance
      character(len=*), intent(in) :: what                !! what is compared
      real(dp) :: err
      character(len=120) :: line

      if (any(shape(a) /= shape(b))) then
         call test_failed(error, what, 'shapes differ')
         return
      end if
      err = maxval(abs(a - b))
      if (maxval(abs(b)) > 0.0_dp) err = err/maxval(abs(b))
      call report(what, err, tol)
      if (.not. (err <= tol)) then
         write (line, '(a,es9.2,a,es9.2)') 'max |a - b| / max |b| =', err, ' > ', tol
         call test_failed(error, what, trim(line))
      end if
   end subroutine check_matrix

   !> Print a measured error and its tolerance when FD_UNIT_REPORT is set.
   subroutine report(what, err, tol)
      character(len=*), intent(in) :: what !! what was compared
      real(dp), intent(in) :: err          !! measured error
      real(dp), intent(in) :: tol          !! tolerance
      integer :: length

      call get_environment_variable('FD_UNIT_REPORT', length=length)
      if (length > 0) write (output_unit, '(es9.2,a,es9.2,2a)') err, ' (tol', tol, ') ', what
   end subroutine report

   !> The directions of a test model's devices from their nodes (as the deck reader sets them).
   subroutine pairs_of(model)
      type(model_type), intent(inout) :: model  !! a model whose devices have node_i and node_j
      integer :: stat

      call set_pair_directions(model, stat)
      if (stat /= 0) error stop "pairs_of: not enough memory"
   end subroutine pairs_of

end module test_fd_helpers
