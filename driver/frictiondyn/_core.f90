!> The f2py layer of frictiondyn: thin, flat entry points over the library's session
!> (fortran/fd_session.f90), with iso_c_binding kinds, explicit-shape arrays and a status.
!> No numerics here, and no state: a session is allocated by fd_session_open (or
!> fd_session_adopt) and handed to the caller as an opaque 64-bit handle (the C address of
!> the session), which the caller passes back to every other entry point and finally to
!> fd_session_close. The deck is read once, by fd_session_open; every buffer the caller
!> fills is sized by a number an entry point returned.
!>
!> Errors never stop the process: every entry point returns a status, and the message of a
!> failure is kept in the session (fetch it with fd_session_text_length and fd_session_text,
!> which = 8). The Python side (frictiondyn/_api.py) turns it into an exception.
!>
!> Text in (a path, a deck, a header) comes as bytes, one byte (0..255) in each element of a
!> c_short array, encoded by the caller (UTF-8 for text, the file system's encoding for
!> paths): f2py's character arguments accept only ASCII str and end a string at a NUL, so
!> text passed as characters could hold no non-ASCII character (a micro sign in a comment,
!> an accented path) and lost what follows a NUL. (f2py's c_int8_t arrays do not compile:
!> it declares them as an undefined C type, signed_char.)
!>
!> status: 0 or the kind of failure, fd_session's status_* (fortran/fd_session.f90: a bad deck
!> or input, a solver failure, misuse, an output file that cannot be written, not enough
!> memory (with the handle 0 when the session itself could not be allocated: then there is no
!> message), a cancelled solve).
!>
!> Threads: fd_session_solve releases the GIL; while it runs, another thread may call
!> fd_session_cancel and fd_session_progress on the same handle (and nothing else).

!> Read and validate a deck (the file `path`, or `text` when from_text /= 0) into a new
!> session; return its handle and the shape of its history. On status 1 the handle is valid
!> (it holds the message) and must be closed too.
subroutine fd_session_open(npath, path, ntext, text, from_text, handle, ncol, nout, status)
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t, c_short
   use fd_session, only: session_type, session_new, session_open, session_open_text, session_shape, &
                         status_input, status_no_memory
   use frictiondyn, only: error_type
   implicit none
   integer(c_int), intent(in) :: npath           !! bytes of the path
   integer(c_short), intent(in) :: path(npath)  !! deck file, or name of a text deck
   integer(c_int), intent(in) :: ntext           !! bytes of the text
   integer(c_short), intent(in) :: text(ntext)  !! deck text (when from_text /= 0)
   integer(c_int), intent(in) :: from_text       !! 1: read text, 0: read the file
   integer(c_int64_t), intent(out) :: handle     !! the new session (0: none, status 5)
   integer(c_int), intent(out) :: ncol           !! columns of the history
   integer(c_int), intent(out) :: nout           !! samples of the history
   integer(c_int), intent(out) :: status         !! 0 or an error code
   !f2py threadsafe
   type(session_type), pointer :: s
   type(error_type), allocatable :: error
   integer :: stat, nc, no
   logical :: history
   character(len=:), allocatable :: path_s, text_s

   ncol = 0; nout = 0
   call session_new(s, handle, stat)
   if (stat /= 0) then
      status = status_no_memory
      return
   end if
   call bytes_text(path, path_s, error)
   if (.not. allocated(error) .and. from_text /= 0) call bytes_text(text, text_s, error)
   if (allocated(error)) then
      ! not enough memory for the text
   else if (from_text /= 0) then
      call session_open_text(s, text_s, path_s, error)
   else
      call session_open(s, path_s, error)
   end if
   if (.not. allocated(error)) call session_shape(s, nc, no, history, error)
   call keep_error(s, error, status_input, status)
   if (status /= 0) return
   ncol = int(nc, c_int); nout = int(no, c_int)
contains
   include 'fd_core_common.inc'
end subroutine fd_session_open

!> A new solved session holding a history and texts given by the caller, to write them with
!> the library's writer (fd_session_write_files).
subroutine fd_session_adopt(ncol, nout, hist, nheader, header, nsummary, summary, handle, status)
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t, c_double, c_short
   use fd_session, only: session_type, session_new, session_adopt, status_no_memory
   use frictiondyn, only: error_type
   implicit none
   integer(c_int), intent(in) :: ncol            !! columns
   integer(c_int), intent(in) :: nout            !! samples
   real(c_double), intent(in) :: hist(ncol, nout) !! history
   integer(c_int), intent(in) :: nheader         !! bytes of the header
   integer(c_short), intent(in) :: header(nheader) !! 'name[unit],...'
   integer(c_int), intent(in) :: nsummary        !! bytes of the summary
   integer(c_short), intent(in) :: summary(nsummary) !! summary text (JSON)
   integer(c_int64_t), intent(out) :: handle     !! the new session (0: none, status 5)
   integer(c_int), intent(out) :: status         !! 0 or an error code
   !f2py threadsafe
   type(session_type), pointer :: s
   type(error_type), allocatable :: error
   integer :: stat
   character(len=:), allocatable :: header_s, summary_s

   call session_new(s, handle, stat)
   if (stat /= 0) then
      status = status_no_memory
      return
   end if
   call bytes_text(header, header_s, error)
   if (.not. allocated(error)) call bytes_text(summary, summary_s, error)
   if (.not. allocated(error)) call session_adopt(s, hist, header_s, summary_s, error)
   call keep_error(s, error, status_no_memory, status)
   if (status /= 0) return
contains
   include 'fd_core_common.inc'
end subroutine fd_session_adopt

!> Free a session. The handle must not be used again.
subroutine fd_session_close(handle)
   use, intrinsic :: iso_c_binding, only: c_int64_t
   use fd_session, only: session_free
   implicit none
   integer(c_int64_t), intent(in) :: handle      !! the session
   !f2py threadsafe
   call session_free(handle)
end subroutine fd_session_close

!> Columns and samples of the session's history, and its &output write_history.
subroutine fd_session_shape(handle, ncol, nout, history, status)
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t
   use fd_session, only: session_type, session_from_handle, session_shape, status_misuse, status_ok
   use frictiondyn, only: error_type
   implicit none
   integer(c_int64_t), intent(in) :: handle      !! the session
   integer(c_int), intent(out) :: ncol           !! columns
   integer(c_int), intent(out) :: nout           !! samples
   integer(c_int), intent(out) :: history        !! 1: &output write_history
   integer(c_int), intent(out) :: status         !! 0 or an error code
   type(session_type), pointer :: s
   type(error_type), allocatable :: error
   integer :: nc, no
   logical :: hist

   ncol = 0; nout = 0; history = 0
   call session_from_handle(handle, s)
   status = merge(int(status_ok, c_int), int(status_misuse, c_int), associated(s))
   if (status /= 0) return
   call session_shape(s, nc, no, hist, error)
   call keep_error(s, error, status_misuse, status)
   if (status /= 0) return
   ncol = int(nc, c_int); nout = int(no, c_int)
   history = merge(1_c_int, 0_c_int, hist)
contains
   include 'fd_core_common.inc'
end subroutine fd_session_shape

!> Run the session's deck. Releases the GIL: sessions may be solved in several threads at once.
!> mode 1: the history goes into `hist` (the caller's (ncol, nout) buffer, Fortran order: the
!> library keeps no copy); 2: the session keeps it (fd_session_history copies it out); 0: no
!> history in memory (the session streams it to its file, or only the summary is wanted).
subroutine fd_session_solve(handle, mode, ncol, nout, hist, status)
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t, c_double
   use fd_session, only: session_type, session_from_handle, session_solve, session_read, &
                         status_cancelled, status_misuse, status_ok, status_solver
   use frictiondyn, only: error_type, stat_cancelled
   implicit none
   integer(c_int64_t), intent(in) :: handle      !! the session
   integer(c_int), intent(in) :: mode            !! 0 none, 1 into hist, 2 kept in the session
   integer(c_int), intent(in) :: ncol            !! columns of hist
   integer(c_int), intent(in) :: nout            !! samples of hist
   real(c_double), intent(inout), target :: hist(ncol, nout) !! the caller's history buffer
   integer(c_int), intent(out) :: status         !! 0 or an error code
   !f2py threadsafe
   type(session_type), pointer :: s
   type(error_type), allocatable :: error
   integer :: code

   call session_from_handle(handle, s)
   status = merge(int(status_ok, c_int), int(status_misuse, c_int), associated(s))
   if (status /= 0) return
   code = merge(status_solver, status_misuse, s%state == session_read)  ! a failure of the solver, or misuse
   select case (mode)
   case (1)
      call session_solve(s, error, buffer=hist)
   case (2)
      call session_solve(s, error, keep=.true.)
   case default
      call session_solve(s, error, keep=.false.)
   end select
   if (allocated(error)) then
      if (error%stat == stat_cancelled) code = status_cancelled
   end if
   call keep_error(s, error, code, status)
   if (status /= 0) return
contains
   include 'fd_core_common.inc'
end subroutine fd_session_solve

!> Keep only some DOFs and devices (1-based, ascending) in the history; before solving.
subroutine fd_session_select(handle, ndof, dofs, ndev, devices, ncol, status)
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t
   use fd_session, only: session_type, session_from_handle, session_select, session_shape, &
                         status_input, status_misuse, status_ok
   use frictiondyn, only: error_type
   implicit none
   integer(c_int64_t), intent(in) :: handle      !! the session
   integer(c_int), intent(in) :: ndof            !! number of DOFs kept
   integer(c_int), intent(in) :: dofs(ndof)      !! the DOFs kept
   integer(c_int), intent(in) :: ndev            !! number of devices kept
   integer(c_int), intent(in) :: devices(ndev)   !! the devices kept
   integer(c_int), intent(out) :: ncol           !! columns of the history now
   integer(c_int), intent(out) :: status         !! 0 or an error code
   type(session_type), pointer :: s
   type(error_type), allocatable :: error
   integer :: nc, no
   logical :: hist

   ncol = 0
   call session_from_handle(handle, s)
   status = merge(int(status_ok, c_int), int(status_misuse, c_int), associated(s))
   if (status /= 0) return
   call session_select(s, int(dofs), int(devices), error)
   if (.not. allocated(error)) call session_shape(s, nc, no, hist, error)
   call keep_error(s, error, status_input, status)
   if (status /= 0) return
   ncol = int(nc, c_int)
contains
   include 'fd_core_common.inc'
end subroutine fd_session_select

!> Numbers of DOFs and devices of the session's deck.
subroutine fd_session_sizes(handle, n_dof, n_devices, status)
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t
   use fd_session, only: session_type, session_from_handle, session_read, status_misuse, status_ok
   use frictiondyn, only: error_type
   use fd_error, only: fatal_error
   implicit none
   integer(c_int64_t), intent(in) :: handle      !! the session
   integer(c_int), intent(out) :: n_dof          !! DOFs
   integer(c_int), intent(out) :: n_devices      !! devices
   integer(c_int), intent(out) :: status         !! 0 or an error code
   type(session_type), pointer :: s
   type(error_type), allocatable :: error

   n_dof = 0; n_devices = 0
   call session_from_handle(handle, s)
   status = merge(int(status_ok, c_int), int(status_misuse, c_int), associated(s))
   if (status /= 0) return
   if (.not. s%from_deck .or. s%state < session_read) call fatal_error(error, 'the session holds no deck')
   call keep_error(s, error, status_misuse, status)
   if (status /= 0) return
   n_dof = int(s%cfg%model%n_dof, c_int)
   n_devices = int(s%cfg%model%n_devices, c_int)
contains
   include 'fd_core_common.inc'
end subroutine fd_session_sizes

!> The DOFs and devices the history keeps now: the deck's &output selection, or the last
!> fd_session_select's (every one when neither selects). The buffers hold n_dof and
!> n_devices numbers (fd_session_sizes; at least 1 each); ndofs, ndevices of them are set.
subroutine fd_session_selection(handle, n_dof, n_devices, dofs, ndofs, devices, ndevices, status)
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t
   use fd_session, only: session_type, session_from_handle, session_read, status_misuse, status_ok
   use frictiondyn, only: error_type
   use fd_error, only: fatal_error
   implicit none
   integer(c_int64_t), intent(in) :: handle      !! the session
   integer(c_int), intent(in) :: n_dof           !! size of dofs
   integer(c_int), intent(in) :: n_devices       !! size of devices
   integer(c_int), intent(out) :: dofs(n_dof)    !! the DOFs kept (1..ndofs)
   integer(c_int), intent(out) :: ndofs          !! how many
   integer(c_int), intent(out) :: devices(n_devices) !! the devices kept (1..ndevices)
   integer(c_int), intent(out) :: ndevices       !! how many
   integer(c_int), intent(out) :: status         !! 0 or an error code
   type(session_type), pointer :: s
   type(error_type), allocatable :: error
   integer :: i, nd, nv

   dofs = 0; devices = 0; ndofs = 0; ndevices = 0
   call session_from_handle(handle, s)
   status = merge(int(status_ok, c_int), int(status_misuse, c_int), associated(s))
   if (status /= 0) return
   if (.not. s%from_deck .or. s%state < session_read) call fatal_error(error, 'the session holds no deck')
   if (.not. allocated(error)) then
      if (s%ctl%select_all) then
         nd = s%cfg%model%n_dof; nv = s%cfg%model%n_devices
      else
         nd = size(s%ctl%dofs); nv = size(s%ctl%devices)
      end if
      if (nd > n_dof .or. nv > n_devices) call fatal_error(error, 'selection buffer too small')
   end if
   call keep_error(s, error, status_misuse, status)
   if (status /= 0) return
   if (s%ctl%select_all) then
      dofs(1:nd) = [(int(i, c_int), i=1, nd)]
      devices(1:nv) = [(int(i, c_int), i=1, nv)]
   else
      dofs(1:nd) = int(s%ctl%dofs, c_int)
      devices(1:nv) = int(s%ctl%devices, c_int)
   end if
   ndofs = int(nd, c_int); ndevices = int(nv, c_int)
contains
   include 'fd_core_common.inc'
end subroutine fd_session_selection

!> Write the history to the deck's output file as the run goes (fd_session_write commits it).
subroutine fd_session_stream(handle, status)
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t
   use fd_session, only: session_type, session_from_handle, session_stream, status_misuse, status_ok
   use frictiondyn, only: error_type
   implicit none
   integer(c_int64_t), intent(in) :: handle      !! the session
   integer(c_int), intent(out) :: status         !! 0 or an error code
   type(session_type), pointer :: s
   type(error_type), allocatable :: error

   call session_from_handle(handle, s)
   status = merge(int(status_ok, c_int), int(status_misuse, c_int), associated(s))
   if (status /= 0) return
   call session_stream(s, error)
   call keep_error(s, error, status_misuse, status)
   if (status /= 0) return
contains
   include 'fd_core_common.inc'
end subroutine fd_session_stream

!> Ask a solve running in another thread to stop (it returns status 6 within a poll).
subroutine fd_session_cancel(handle)
   use, intrinsic :: iso_c_binding, only: c_int64_t
   use fd_session, only: session_type, session_from_handle, session_cancel
   implicit none
   integer(c_int64_t), intent(in) :: handle      !! the session
   !f2py threadsafe
   type(session_type), pointer :: s

   call session_from_handle(handle, s)
   if (associated(s)) call session_cancel(s)
end subroutine fd_session_cancel

!> The time a solve running in another thread has reached, and the run's duration [s].
subroutine fd_session_progress(handle, t, duration)
   use, intrinsic :: iso_c_binding, only: c_int64_t, c_double
   use fd_session, only: session_type, session_from_handle, session_progress
   use frictiondyn, only: dp
   implicit none
   integer(c_int64_t), intent(in) :: handle      !! the session
   real(c_double), intent(out) :: t              !! time reached [s]
   real(c_double), intent(out) :: duration       !! duration [s]
   !f2py threadsafe
   type(session_type), pointer :: s
   real(dp) :: tt, dd

   t = 0.0_c_double; duration = 0.0_c_double
   call session_from_handle(handle, s)
   if (.not. associated(s)) return
   call session_progress(s, tt, dd)
   t = real(tt, c_double); duration = real(dd, c_double)
end subroutine fd_session_progress

!> Copy the history of a solved session into `hist` (its shape from fd_session_shape).
subroutine fd_session_history(handle, ncol, nout, hist, status)
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t, c_double
   use fd_session, only: session_type, session_from_handle, session_solved, status_misuse, status_ok
   use frictiondyn, only: error_type
   use fd_error, only: fatal_error
   implicit none
   integer(c_int64_t), intent(in) :: handle      !! the session
   integer(c_int), intent(in) :: ncol            !! columns
   integer(c_int), intent(in) :: nout            !! samples
   real(c_double), intent(out) :: hist(ncol, nout) !! the history
   integer(c_int), intent(out) :: status         !! 0 or an error code
   !f2py threadsafe
   type(session_type), pointer :: s
   type(error_type), allocatable :: error

   hist = 0.0_c_double
   call session_from_handle(handle, s)
   status = merge(int(status_ok, c_int), int(status_misuse, c_int), associated(s))
   if (status /= 0) return
   if (s%state /= session_solved) then
      call fatal_error(error, 'cannot give the history: the session is not solved')
   else if (s%res%ncol /= ncol .or. s%res%nout /= nout) then
      call fatal_error(error, 'history buffer of the wrong shape')
   end if
   call keep_error(s, error, status_misuse, status)
   if (status /= 0) return
   hist = real(s%res%hist, c_double)
contains
   include 'fd_core_common.inc'
end subroutine fd_session_history

!> Length of one of the session's texts (which: fd_session's text_*, fortran/fd_session.f90:
!> history header, summary JSON, &output dir and name, history and summary paths, deck,
!> message of the last error).
subroutine fd_session_text_length(handle, which, length, status)
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t
   use fd_session, only: session_type, session_from_handle, session_text, status_misuse, status_ok
   use frictiondyn, only: error_type
   implicit none
   integer(c_int64_t), intent(in) :: handle      !! the session
   integer(c_int), intent(in) :: which           !! which text
   integer(c_int), intent(out) :: length         !! its length in bytes
   integer(c_int), intent(out) :: status         !! 0 or an error code
   type(session_type), pointer :: s
   type(error_type), allocatable :: error
   character(len=:), allocatable :: str

   length = 0
   call session_from_handle(handle, s)
   status = merge(int(status_ok, c_int), int(status_misuse, c_int), associated(s))
   if (status /= 0) return
   call session_text(s, int(which), str, error)
   call keep_error(s, error, status_misuse, status)
   if (status /= 0) return
   length = int(len(str), c_int)
contains
   include 'fd_core_common.inc'
end subroutine fd_session_text_length

!> One of the session's texts (see fd_session_text_length) into `buf` of exactly its length.
subroutine fd_session_text(handle, which, length, buf, status)
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t, c_char
   use fd_session, only: session_type, session_from_handle, session_text, status_misuse, status_ok
   use frictiondyn, only: error_type
   use fd_error, only: fatal_error
   implicit none
   integer(c_int64_t), intent(in) :: handle      !! the session
   integer(c_int), intent(in) :: which           !! which text
   integer(c_int), intent(in) :: length          !! its length, from fd_session_text_length
   character(kind=c_char, len=1), intent(out) :: buf(length) !! the text
   integer(c_int), intent(out) :: status         !! 0 or an error code
   type(session_type), pointer :: s
   type(error_type), allocatable :: error
   character(len=:), allocatable :: str
   integer :: i

   buf = ' '
   call session_from_handle(handle, s)
   status = merge(int(status_ok, c_int), int(status_misuse, c_int), associated(s))
   if (status /= 0) return
   call session_text(s, int(which), str, error)
   if (.not. allocated(error) .and. len(str) /= length) &
      call fatal_error(error, 'text buffer of the wrong length')
   call keep_error(s, error, status_misuse, status)
   if (status /= 0) return
   do i = 1, len(str)
      buf(i) = str(i:i)
   end do
contains
   include 'fd_core_common.inc'
end subroutine fd_session_text

!> Write the outputs into `dir` instead of the deck's &output dir.
subroutine fd_session_set_output_dir(handle, ndir, dir, status)
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t, c_short
   use fd_session, only: session_type, session_from_handle, session_set_output_dir, status_misuse, status_ok
   use frictiondyn, only: error_type
   implicit none
   integer(c_int64_t), intent(in) :: handle      !! the session
   integer(c_int), intent(in) :: ndir            !! bytes of the directory
   integer(c_short), intent(in) :: dir(ndir)    !! output directory
   integer(c_int), intent(out) :: status         !! 0 or an error code
   type(session_type), pointer :: s
   type(error_type), allocatable :: error
   character(len=:), allocatable :: dir_s

   call session_from_handle(handle, s)
   status = merge(int(status_ok, c_int), int(status_misuse, c_int), associated(s))
   if (status /= 0) return
   call bytes_text(dir, dir_s, error)
   if (.not. allocated(error)) call session_set_output_dir(s, dir_s, error)
   call keep_error(s, error, status_misuse, status)
   if (status /= 0) return
contains
   include 'fd_core_common.inc'
end subroutine fd_session_set_output_dir

!> Write the history CSV and the summary of a solved session as the executable does (the
!> library's writer, the deck's &output settings). The history is `hist` when use_hist /= 0
!> (the caller's buffer of fd_session_solve), else the session's (or its streamed file).
subroutine fd_session_write(handle, use_hist, ncol, nout, hist, status)
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t, c_double
   use fd_session, only: session_type, session_from_handle, session_write, session_solved, &
                         status_misuse, status_ok, status_output
   use frictiondyn, only: error_type
   implicit none
   integer(c_int64_t), intent(in) :: handle      !! the session
   integer(c_int), intent(in) :: use_hist        !! 1: the history is hist
   integer(c_int), intent(in) :: ncol            !! columns of hist
   integer(c_int), intent(in) :: nout            !! samples of hist
   real(c_double), intent(in) :: hist(ncol, nout) !! the history (when use_hist = 1)
   integer(c_int), intent(out) :: status         !! 0 or an error code
   !f2py threadsafe
   type(session_type), pointer :: s
   type(error_type), allocatable :: error
   integer :: code

   call session_from_handle(handle, s)
   status = merge(int(status_ok, c_int), int(status_misuse, c_int), associated(s))
   if (status /= 0) return
   code = merge(status_output, status_misuse, s%state == session_solved)
   if (use_hist /= 0) then
      call session_write(s, error, hist)
   else
      call session_write(s, error)
   end if
   call keep_error(s, error, code, status)
   if (status /= 0) return
contains
   include 'fd_core_common.inc'
end subroutine fd_session_write

!> Write the history (when history /= 0: `hist` when use_hist /= 0, else the session's) to
!> `hist_path` and the summary to `summ_path` with the library's writer.
subroutine fd_session_write_files(handle, nhist, hist_path, nsumm, summ_path, history, use_hist, ncol, nout, hist, status)
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t, c_double, c_short
   use fd_session, only: session_type, session_from_handle, session_write_files, session_solved, &
                         status_misuse, status_ok, status_output
   use frictiondyn, only: error_type
   implicit none
   integer(c_int64_t), intent(in) :: handle      !! the session
   integer(c_int), intent(in) :: nhist           !! bytes of hist_path
   integer(c_short), intent(in) :: hist_path(nhist) !! the history CSV
   integer(c_int), intent(in) :: nsumm           !! bytes of summ_path
   integer(c_short), intent(in) :: summ_path(nsumm) !! the summary file
   integer(c_int), intent(in) :: history         !! 1: write the history too
   integer(c_int), intent(in) :: use_hist        !! 1: the history is hist
   integer(c_int), intent(in) :: ncol            !! columns of hist
   integer(c_int), intent(in) :: nout            !! samples of hist
   real(c_double), intent(in) :: hist(ncol, nout) !! the history (when use_hist = 1)
   integer(c_int), intent(out) :: status         !! 0 or an error code
   !f2py threadsafe
   type(session_type), pointer :: s
   type(error_type), allocatable :: error
   integer :: code
   character(len=:), allocatable :: hist_s, summ_s

   call session_from_handle(handle, s)
   status = merge(int(status_ok, c_int), int(status_misuse, c_int), associated(s))
   if (status /= 0) return
   code = merge(status_output, status_misuse, s%state == session_solved)
   call bytes_text(hist_path, hist_s, error)
   if (.not. allocated(error)) call bytes_text(summ_path, summ_s, error)
   if (.not. allocated(error)) then
      if (use_hist /= 0) then
         call session_write_files(s, hist_s, summ_s, history /= 0, error, hist)
      else
         call session_write_files(s, hist_s, summ_s, history /= 0, error)
      end if
   end if
   call keep_error(s, error, code, status)
   if (status /= 0) return
contains
   include 'fd_core_common.inc'
end subroutine fd_session_write_files

!> The elastic response spectrum of the session's recorded table motion (see session_spectrum).
subroutine fd_session_spectrum(handle, nper, periods, xi, sd, psv, psa, sa, status)
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t, c_double
   use fd_session, only: session_type, session_from_handle, session_spectrum, status_input, status_misuse, &
                         status_ok
   use frictiondyn, only: error_type
   implicit none
   integer(c_int64_t), intent(in) :: handle      !! the session
   integer(c_int), intent(in) :: nper            !! number of periods
   real(c_double), intent(in) :: periods(nper)   !! periods [s]
   real(c_double), intent(in) :: xi              !! damping ratio
   real(c_double), intent(out) :: sd(nper)       !! peak relative displacement [m]
   real(c_double), intent(out) :: psv(nper)      !! pseudo-velocity [m/s]
   real(c_double), intent(out) :: psa(nper)      !! pseudo-acceleration [m/s2]
   real(c_double), intent(out) :: sa(nper)       !! peak absolute acceleration [m/s2]
   integer(c_int), intent(out) :: status         !! 0 or an error code
   !f2py threadsafe
   type(session_type), pointer :: s
   type(error_type), allocatable :: error

   sd = 0; psv = 0; psa = 0; sa = 0
   call session_from_handle(handle, s)
   status = merge(int(status_ok, c_int), int(status_misuse, c_int), associated(s))
   if (status /= 0) return
   call session_spectrum(s, periods, xi, sd, psv, psa, sa, error)
   call keep_error(s, error, status_input, status)
contains
   include 'fd_core_common.inc'
end subroutine fd_session_spectrum
