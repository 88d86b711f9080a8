!> The history CSV written as the run goes: a header, then one row per sample, formatted
!> into a buffer of about 1 MB and written with POSIX calls when it fills, so that the
!> history never has to be held in memory. Rows are byte for byte those of the whole-history
!> writer (ES24.16E3, comma separated; fd_stream_c.c formats them without the heap: the
!> time-step loop allocates nothing). The file is created exclusively under a temporary name
!> the caller chooses; stream_close flushes and closes it, and the caller renames it into place
!> (stream_commit) or removes it (stream_discard). A failed write is kept in the stream (its
!> errno) and reported by stream_failed / stream_close: the loop polls it, never prints. The
!> file calls are fd_fileops.c's (the writer's), the row formatting fd_stream_c.c's.
module fd_history_stream
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_long, c_double, c_null_char
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error
   use fd_fileops, only: c_file_create, c_file_write, c_file_close, c_unlink, c_rename, os_error
   use fd_row_sink, only: row_sink
   implicit none
   private

   public :: history_stream, stream_open, stream_row, stream_close, stream_discard, stream_commit
   public :: stream_failed, stream_is_open, format_row, history_file_sink

   !> Bytes a value takes in a row: 24 characters and a comma (or the newline).
   integer, parameter, public :: stream_value_width = 25
   !> Size of the output buffer [bytes] (at least one row).
   integer, parameter :: buffer_bytes = 1048576

   !> One history file being written; as the observer's row sink (fd_row_sink, made by
   !> history_file_sink) it creates `dest` when begun.
   type, extends(row_sink) :: history_stream
      integer(c_int) :: fd = -1                      !! file descriptor (-1: not open)
      character(len=:), allocatable :: path          !! the (temporary) file written
      character(kind=c_char, len=:), allocatable :: buf !! output buffer
      integer :: pos = 0                             !! bytes used in buf
      integer :: ncol = 0                            !! values a row
      integer(c_int) :: err = 0                      !! errno of a failed write (0: none)
      character(len=:), allocatable :: dest          !! the file the sink creates when begun
   contains
      procedure :: begin => sink_begin
      procedure :: put => sink_put
      procedure :: failed => sink_failed
      procedure :: finish => sink_finish
      procedure :: discard => sink_discard
   end type history_stream

   interface
      !> Pure: it writes buf and nbytes only, from x only (no state, no I/O).
      pure subroutine c_format_row(x, n, buf, nbytes) bind(c, name='fd_format_row')
         import :: c_double, c_int, c_char, c_long
         real(c_double), intent(in) :: x(*)
         integer(c_int), value :: n
         character(kind=c_char), intent(inout) :: buf(*)
         integer(c_long), intent(out) :: nbytes
      end subroutine c_format_row
   end interface

contains

   !> Create `path` (it must not exist) and write the header line; allocates the buffer.
   subroutine stream_open(st, path, header, ncol, error)
      type(history_stream), intent(inout) :: st          !! the stream (closed)
      character(len=*), intent(in) :: path                !! file to create
      character(len=*), intent(in) :: header              !! header line, without newline
      integer, intent(in) :: ncol                         !! values a row
      type(error_type), allocatable, intent(out) :: error !! cannot create or write
      integer(c_int) :: err

      if (st%fd >= 0) then
         call fatal_error(error, "stream_open: a stream is already open on '"//st%path//"'")
         return
      end if
      err = c_file_create(path//c_null_char, st%fd)
      if (err /= 0) then
         st%fd = -1
         call os_error(error, "cannot create '"//path//"'", err)
         return
      end if
      st%path = path
      st%ncol = ncol
      st%err = 0
      st%pos = 0
      allocate (character(kind=c_char, len=max(buffer_bytes, stream_value_width*max(ncol, 1), &
                                               len(header) + 1)) :: st%buf)
      st%buf(1:len(header)) = header
      st%buf(len(header) + 1:len(header) + 1) = achar(10)
      st%pos = len(header) + 1
   end subroutine stream_open

   !> Append one row (formatted into the buffer; written out when the buffer is full).
   !> Allocates nothing. After a failed write the stream only records the failure.
   subroutine stream_row(st, row)
      type(history_stream), intent(inout) :: st   !! an open stream
      real(dp), intent(in) :: row(:)              !! the row's values, size ncol
      integer(c_long) :: nb

      if (st%fd < 0 .or. st%err /= 0) return
      if (st%pos + stream_value_width*size(row) > len(st%buf)) call flush_buffer(st)
      if (st%err /= 0) return
      call c_format_row(row, int(size(row), c_int), st%buf(st%pos + 1:), nb)
      st%pos = st%pos + int(nb)
   end subroutine stream_row

   !> The text of a row as the stream writes it (25 characters a value, the last a newline).
   pure subroutine format_row(row, text)
      real(dp), intent(in) :: row(:)                        !! values
      character(kind=c_char, len=*), intent(inout) :: text  !! at least 25 size(row) characters
      integer(c_long) :: nb

      call c_format_row(row, int(size(row), c_int), text, nb)
   end subroutine format_row

   subroutine flush_buffer(st)
      type(history_stream), intent(inout) :: st

      if (st%pos == 0 .or. st%err /= 0) return
      st%err = c_file_write(st%fd, st%buf, int(st%pos, c_long))
      st%pos = 0
   end subroutine flush_buffer

   !> Whether a write has failed (the run should stop).
   pure logical function stream_failed(st)
      type(history_stream), intent(in) :: st  !! the stream

      stream_failed = st%err /= 0
   end function stream_failed

   !> Whether the stream is open.
   pure logical function stream_is_open(st)
      type(history_stream), intent(in) :: st  !! the stream

      stream_is_open = st%fd >= 0
   end function stream_is_open

   !> Write what is buffered, flush to disk and close. On failure (a write that failed
   !> earlier included) the file is removed and the error names it and the reason.
   subroutine stream_close(st, error)
      type(history_stream), intent(inout) :: st          !! an open stream
      type(error_type), allocatable, intent(out) :: error !! the file could not be written
      integer(c_int) :: err

      if (st%fd < 0) then
         call fatal_error(error, "stream_close: no stream is open")
         return
      end if
      call flush_buffer(st)
      err = c_file_close(st%fd)
      st%fd = -1
      if (st%err == 0) st%err = err
      if (allocated(st%buf)) deallocate (st%buf)
      if (st%err /= 0) then
         err = c_unlink(st%path//c_null_char)
         call os_error(error, "cannot write '"//st%path//"'", st%err)
      end if
   end subroutine stream_close

   !> Close (if open) and remove the file: nothing is left of an abandoned stream.
   subroutine stream_discard(st)
      type(history_stream), intent(inout) :: st   !! the stream
      integer(c_int) :: err

      if (st%fd >= 0) err = c_file_close(st%fd)
      st%fd = -1
      if (allocated(st%buf)) deallocate (st%buf)
      if (allocated(st%path)) then
         err = c_unlink(st%path//c_null_char)
         deallocate (st%path)
      end if
      st%pos = 0
   end subroutine stream_discard

   !> Rename the closed stream's file to `final` (replacing a file of that name).
   subroutine stream_commit(st, final, error)
      type(history_stream), intent(inout) :: st          !! a closed stream
      character(len=*), intent(in) :: final               !! the name it gets
      type(error_type), allocatable, intent(out) :: error !! cannot rename
      integer(c_int) :: err

      if (st%fd >= 0 .or. .not. allocated(st%path)) then
         call fatal_error(error, "stream_commit: the stream is open or was never written")
         return
      end if
      err = c_rename(st%path//c_null_char, final//c_null_char)
      if (err /= 0) then
         call os_error(error, "cannot rename '"//st%path//"' to '"//final//"'", err)
         err = c_unlink(st%path//c_null_char)
      end if
      deallocate (st%path)
   end subroutine stream_commit

   !> A row sink that writes the history file `path` (created when the run begins it, under
   !> the name the caller chose: a temporary one, committed by write_output_files).
   subroutine history_file_sink(path, sink)
      character(len=*), intent(in) :: path                   !! the file to create
      class(row_sink), allocatable, intent(out) :: sink      !! the sink

      allocate (history_stream :: sink)
      select type (sink)
      type is (history_stream)
         sink%dest = path
      end select
   end subroutine history_file_sink

   !> The sink begun: its file created (stream_open), the header written.
   subroutine sink_begin(sink, header, ncol, error)
      class(history_stream), intent(inout) :: sink        !! the sink
      character(len=*), intent(in) :: header              !! header line, without newline
      integer, intent(in) :: ncol                         !! values a row
      type(error_type), allocatable, intent(out) :: error !! cannot create or write
      character(len=:), allocatable :: dest

      if (.not. allocated(sink%dest)) then
         call fatal_error(error, "the history sink names no file")
         return
      end if
      dest = sink%dest
      call stream_open(sink, dest, header, ncol, error)
   end subroutine sink_begin

   !> One row (stream_row).
   subroutine sink_put(sink, row)
      class(history_stream), intent(inout) :: sink  !! the sink
      real(dp), intent(in) :: row(:)                !! the row's values

      call stream_row(sink, row)
   end subroutine sink_put

   !> Whether a write has failed (stream_failed).
   logical function sink_failed(sink)
      class(history_stream), intent(in) :: sink     !! the sink

      sink_failed = stream_failed(sink)
   end function sink_failed

   !> Flush, close (stream_close); on failure the file is removed and the error names it.
   subroutine sink_finish(sink, error)
      class(history_stream), intent(inout) :: sink        !! the sink
      type(error_type), allocatable, intent(out) :: error !! the file could not be written

      call stream_close(sink, error)
   end subroutine sink_finish

   !> Close if open and remove the file (stream_discard).
   subroutine sink_discard(sink)
      class(history_stream), intent(inout) :: sink  !! the sink

      call stream_discard(sink)
   end subroutine sink_discard

end module fd_history_stream
