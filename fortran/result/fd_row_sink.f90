!> Where the rows of a history go while a run goes, as the observer sees it: an abstract sink
!> that is begun with the header line, takes one row at a time (allocating nothing), says
!> whether a write has failed (the run then stops), and is finished (everything written, or
!> an error naming what could not be) or discarded (nothing left behind). The run's control
!> holds one when the caller wants the rows written as the run goes; the io layer provides the
!> history file (fd_history_stream), so that the result layer writes rows without knowing files.
module fd_row_sink
   use fd_kinds, only: dp
   use fd_error, only: error_type
   implicit none
   private

   public :: row_sink

   !> A destination of history rows.
   type, abstract :: row_sink
   contains
      procedure(sink_begin), deferred :: begin      !! start: the header line, the values a row
      procedure(sink_put), deferred :: put          !! one row
      procedure(sink_failed), deferred :: failed    !! a write has failed
      procedure(sink_finish), deferred :: finish    !! everything written, or the error
      procedure(sink_discard), deferred :: discard  !! nothing left behind
   end type row_sink

   abstract interface
      !> Start the sink: the header line (without newline) and the values of a row.
      subroutine sink_begin(sink, header, ncol, error)
         import :: row_sink, error_type
         class(row_sink), intent(inout) :: sink              !! the sink
         character(len=*), intent(in) :: header              !! 'name[unit],...' of each column
         integer, intent(in) :: ncol                         !! values a row
         type(error_type), allocatable, intent(out) :: error !! cannot start
      end subroutine sink_begin
      !> One row (allocates nothing; after a failed write the sink only records the failure).
      subroutine sink_put(sink, row)
         import :: row_sink, dp
         class(row_sink), intent(inout) :: sink  !! the sink
         real(dp), intent(in) :: row(:)          !! the row's values
      end subroutine sink_put
      !> Whether a write has failed.
      logical function sink_failed(sink)
         import :: row_sink
         class(row_sink), intent(in) :: sink     !! the sink
      end function sink_failed
      !> Write what is pending and end; on failure nothing is left and the error names why.
      subroutine sink_finish(sink, error)
         import :: row_sink, error_type
         class(row_sink), intent(inout) :: sink              !! the sink
         type(error_type), allocatable, intent(out) :: error !! what could not be written
      end subroutine sink_finish
      !> Abandon the sink: nothing of it is left.
      subroutine sink_discard(sink)
         import :: row_sink
         class(row_sink), intent(inout) :: sink  !! the sink
      end subroutine sink_discard
   end interface

end module fd_row_sink
