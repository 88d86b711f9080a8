!> What the caller of a run controls while it goes, for every technique (the observer
!> applies it): which history columns are kept and where their rows go (the result's
!> history, a buffer the caller owns, a row sink such as a file written as the run goes), a request to stop
!> (set from another thread, polled by the solver), and the progress the run reports (the
!> time reached, read from another thread; a callback at a set interval of wall-clock time).
!> A run without a control keeps every column in the result's history, as before.
!>
!> Threads: `cancel` and `time` are the only components touched by another thread while a
!> run goes, each a single aligned word written by one side and read by the other; the
!> solver reads `cancel` through a volatile dummy (cancel_requested), so that it is read
!> from memory at every poll.
module fd_run_control
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int
   use fd_row_sink, only: row_sink
   implicit none
   private

   public :: run_control, progress_callback, cancel_requested, select_history, control_reset
   public :: stat_cancelled

   !> error%stat of a run stopped by a cancel request.
   integer, parameter :: stat_cancelled = 130

   abstract interface
      !> Called now and then during a run with the time reached and the duration [s].
      subroutine progress_callback(t, duration)
         import :: dp
         real(dp), intent(in) :: t         !! time reached [s]
         real(dp), intent(in) :: duration  !! duration of the run [s]
      end subroutine progress_callback
   end interface

   !> The control of one run.
   type :: run_control
      ! which history columns: t and ag always, then (u, v, aabs) of the kept DOFs and
      ! (s, sdot, F, phase) of the kept devices
      logical :: select_all = .true.                  !! every DOF and device (dofs, devices unused)
      integer, allocatable :: dofs(:)                 !! DOFs kept, ascending (1-based)
      integer, allocatable :: devices(:)              !! devices kept, ascending (1-based)
      ! where the rows go
      logical :: keep = .true.                        !! into the result's history (memory)
      real(dp), pointer :: buffer(:, :) => null()     !! into the caller's (ncol, nout) buffer
      class(row_sink), allocatable :: sink            !! into this sink as the run goes (the caller's:
                                                      !! the history file of fd_history_stream)
      ! stop and progress
      integer :: cancel = 0                           !! set non-zero (another thread) to stop
      real(dp) :: time = 0.0_dp                       !! time reached [s] (written by the run)
      real(dp) :: duration = 0.0_dp                   !! duration of the run [s]
      procedure(progress_callback), pointer, nopass :: on_progress => null() !! progress report
      real(dp) :: progress_interval = 0.1_dp          !! wall-clock seconds between reports
      ! the first value not finite in a row that went only to the buffer or the file (the
      ! result's rows are checked at the end): run_config_solve makes it an error
      integer :: bad_column = 0                       !! its column (0: none)
      real(dp) :: bad_time = 0.0_dp                   !! its row's time [s]
      real(dp) :: bad_value = 0.0_dp                  !! the value
   end type run_control

contains

   !> Whether a stop was requested: `flag` is read from memory at every call.
   logical function cancel_requested(flag)
      integer, intent(inout), volatile :: flag   !! the control's cancel word (not changed)

      cancel_requested = flag /= 0
   end function cancel_requested

   !> Keep only some DOFs and devices in the history (each list ascending, without repeats,
   !> within 1..n_dof and 1..n_devices; an empty list keeps none of them).
   subroutine select_history(ctl, dofs, devices, n_dof, n_devices, error)
      type(run_control), intent(inout) :: ctl            !! the control
      integer, intent(in) :: dofs(:)                     !! DOFs to keep
      integer, intent(in) :: devices(:)                  !! devices to keep
      integer, intent(in) :: n_dof                       !! DOFs of the model
      integer, intent(in) :: n_devices                   !! devices of the model
      type(error_type), allocatable, intent(out) :: error !! a number out of range or repeated

      call check_list('DOF', dofs, n_dof, error)
      if (allocated(error)) return
      call check_list('device', devices, n_devices, error)
      if (allocated(error)) return
      ctl%select_all = .false.
      ctl%dofs = dofs
      ctl%devices = devices
   contains
      subroutine check_list(what, list, n, error)
         character(len=*), intent(in) :: what
         integer, intent(in) :: list(:), n
         type(error_type), allocatable, intent(out) :: error
         integer :: i
         do i = 1, size(list)
            if (list(i) < 1 .or. list(i) > n) then
               call fatal_error(error, "history selection: "//what//" "//trim(fmt_int(list(i)))// &
                                " is not in 1.."//trim(fmt_int(n)))
               return
            end if
         end do
         do i = 2, size(list)
            if (list(i) <= list(i - 1)) then
               call fatal_error(error, "history selection: the "//what//"s must be given in increasing "// &
                                "order without repeats ("//trim(fmt_int(list(i - 1)))//" then "// &
                                trim(fmt_int(list(i)))//")")
               return
            end if
         end do
      end subroutine check_list
   end subroutine select_history

   !> Clear what a run left in the control (the stop request, the time, the buffer, a value
   !> not finite), keeping the selection and the settings.
   subroutine control_reset(ctl)
      type(run_control), intent(inout) :: ctl   !! the control

      ctl%cancel = 0
      ctl%time = 0.0_dp
      ctl%bad_column = 0
      nullify (ctl%buffer)
   end subroutine control_reset

end module fd_run_control
