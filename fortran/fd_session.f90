!> A session: one deck read once, then solved, queried and written, all through one object
!> the caller owns. It is what the Python extension holds between calls (as an opaque handle),
!> so that the deck and its record are read exactly once per run and every buffer the caller
!> needs is sized here, from the deck and the result, never guessed.
!>
!> Life cycle: session_open (or session_open_text) reads and validates the deck; session_solve
!> runs it; session_text, session_shape and the result's history give what it produced;
!> session_write writes the outputs with the library's writer. session_adopt makes a solved
!> session from a history and texts given by the caller, to write them with the same writer.
!>
!> Room to grow: a cancel flag and the current time of a running solve belong here (the solver
!> polls and updates them through its observer), as does a choice of the DOFs and devices to keep
!> (set between open and solve; session_shape then reports the reduced history).
module fd_session
   use, intrinsic :: iso_c_binding, only: c_int64_t, c_intptr_t, c_ptr, c_loc, c_f_pointer
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int
   use frictiondyn, only: run_config, result_type, read_deck, read_deck_string, run_config_solve, &
                          shape_of, summary_json, history_header, output_paths, write_outputs, &
                          write_output_files
   implicit none
   private

   public :: session_type, session_open, session_open_text, session_adopt, session_solve
   public :: session_shape, session_text, session_set_output_dir, session_write, session_write_files
   public :: session_new, session_from_handle, session_free
   public :: text_header, text_summary, text_output_dir, text_output_name, text_history_path, &
             text_summary_path, text_deck, text_error

   ! what a session holds
   integer, parameter :: state_empty = 0   !! nothing read (or the deck was rejected)
   integer, parameter, public :: session_read = 1    !! the deck is read, not solved
   integer, parameter, public :: session_solved = 2  !! the result is there
   integer, parameter :: state_failed = 3  !! the solver failed: nothing more to get

   ! the texts a session gives (session_text)
   integer, parameter :: text_header = 1        !! history header 'name[unit],...'
   integer, parameter :: text_summary = 2       !! summary JSON, as written to the summary file
   integer, parameter :: text_output_dir = 3    !! &output dir (or the directory set since)
   integer, parameter :: text_output_name = 4   !! &output name
   integer, parameter :: text_history_path = 5  !! the history CSV session_write writes
   integer, parameter :: text_summary_path = 6  !! the summary file session_write writes
   integer, parameter :: text_deck = 7          !! the deck's path (or name, for a text deck)
   integer, parameter :: text_error = 8         !! message of the last error kept in the session

   !> One deck, its run and its outputs.
   type :: session_type
      integer :: state = state_empty                  !! what the session holds
      logical :: from_deck = .false.                  !! read from a deck (not adopted)
      type(run_config) :: cfg                         !! what the deck defines
      type(result_type) :: res                        !! the run's result, once solved
      character(len=:), allocatable :: header         !! history header, once solved
      character(len=:), allocatable :: summary        !! summary JSON, once solved
      type(error_type), allocatable :: error          !! last error, for a caller that keeps it
                                                      !! here (the C layer); the procedures below
                                                      !! return theirs as an argument
   end type session_type

contains

   !> Allocate a session on the heap and give its handle: its C address held in a 64-bit
   !> integer, for a caller across a C interface (the Python extension). The caller owns it
   !> and frees it with session_free.
   subroutine session_new(s, handle, stat)
      type(session_type), pointer, intent(out) :: s   !! the new session
      integer(c_int64_t), intent(out) :: handle       !! its handle (0 when stat /= 0)
      integer, intent(out) :: stat                    !! 0, or not enough memory
      handle = 0
      nullify (s)
      allocate (s, stat=stat)
      if (stat /= 0) return
      handle = int(transfer(c_loc(s), 0_c_intptr_t), c_int64_t)
   end subroutine session_new

   !> The session of a handle from session_new (not associated for the handle 0).
   subroutine session_from_handle(handle, s)
      integer(c_int64_t), intent(in) :: handle        !! the handle
      type(session_type), pointer, intent(out) :: s   !! its session
      type(c_ptr) :: p
      nullify (s)
      if (handle == 0) return
      p = transfer(int(handle, c_intptr_t), p)
      call c_f_pointer(p, s)
   end subroutine session_from_handle

   !> Free the session of a handle from session_new; the handle must not be used again.
   subroutine session_free(handle)
      integer(c_int64_t), intent(in) :: handle        !! the handle (0: nothing to free)
      type(session_type), pointer :: s
      call session_from_handle(handle, s)
      if (associated(s)) deallocate (s)
   end subroutine session_free

   !> Read and validate a deck file into a fresh session.
   subroutine session_open(s, path, error)
      type(session_type), intent(inout) :: s              !! the session (any previous content is dropped)
      character(len=*), intent(in) :: path                !! deck file
      type(error_type), allocatable, intent(out) :: error !! bad or missing deck or record
      call reset(s)
      call read_deck(path, s%cfg, error)
      if (allocated(error)) return
      s%state = session_read
      s%from_deck = .true.
   end subroutine session_open

   !> Read and validate a deck given as text into a fresh session; `path` names it in messages
   !> and is the base of a relative record_file.
   subroutine session_open_text(s, text, path, error)
      type(session_type), intent(inout) :: s              !! the session (any previous content is dropped)
      character(len=*), intent(in) :: text                !! the deck, lines separated by newlines
      character(len=*), intent(in) :: path                !! name of the deck
      type(error_type), allocatable, intent(out) :: error !! bad deck or record
      call reset(s)
      call read_deck_string(text, path, s%cfg, error)
      if (allocated(error)) return
      s%state = session_read
      s%from_deck = .true.
   end subroutine session_open_text

   !> A solved session holding a history and texts given by the caller (no deck): what
   !> session_write_files then writes with the library's writer.
   subroutine session_adopt(s, hist, header, summary, error)
      type(session_type), intent(inout) :: s              !! the session (any previous content is dropped)
      real(dp), intent(in) :: hist(:, :)                  !! history (columns, samples)
      character(len=*), intent(in) :: header              !! 'name[unit],...', one per column
      character(len=*), intent(in) :: summary             !! summary text, written as it is
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      integer :: stat
      call reset(s)
      s%res%ncol = size(hist, 1)
      s%res%nout = size(hist, 2)
      allocate (s%res%hist(s%res%ncol, s%res%nout), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, 'not enough memory for a history of '//trim(fmt_int(s%res%nout))// &
                          ' samples of '//trim(fmt_int(s%res%ncol))//' columns')
         return
      end if
      s%res%hist = hist
      s%header = header
      s%summary = summary
      s%state = session_solved
   end subroutine session_adopt

   !> Run the session's deck; its history, header and summary are then available.
   subroutine session_solve(s, error)
      type(session_type), intent(inout) :: s              !! a session with a deck read
      type(error_type), allocatable, intent(out) :: error !! wrong state, or the solver failed
      call need(s, session_read, 'solve', error)
      if (allocated(error)) return
      call run_config_solve(s%cfg, s%res, error)
      if (allocated(error)) then
         s%state = state_failed
         error%message = s%cfg%deck_path//": "//error%message   ! as the executable says it
         return
      end if
      call history_header(s%res, s%header)
      call summary_json(s%cfg%model, s%res, s%cfg%deck_path, s%summary, s%cfg%record)
      s%state = session_solved
   end subroutine session_solve

   !> Columns and samples of the history (that the run will produce, or has produced).
   subroutine session_shape(s, ncol, nout, history, error)
      type(session_type), intent(in) :: s                !! an open session
      integer, intent(out) :: ncol                        !! columns
      integer, intent(out) :: nout                        !! samples
      logical, intent(out) :: history                     !! the deck's &output write_history
      type(error_type), allocatable, intent(out) :: error !! nothing open
      ncol = 0; nout = 0; history = .false.
      select case (s%state)
      case (session_read, state_failed)
         call shape_of(s%cfg, ncol, nout)
      case (session_solved)
         ncol = s%res%ncol
         nout = s%res%nout
      case default
         call fatal_error(error, 'the session holds no deck')
         return
      end select
      if (s%from_deck) history = s%cfg%out%history
   end subroutine session_shape

   !> One of the session's texts (text_header, text_summary, ...; see the parameters).
   subroutine session_text(s, which, text, error)
      type(session_type), intent(in) :: s                 !! the session
      integer, intent(in) :: which                        !! which text
      character(len=:), allocatable, intent(out) :: text  !! the text
      type(error_type), allocatable, intent(out) :: error !! not available in this state
      character(len=:), allocatable :: hist, summ

      text = ''
      select case (which)
      case (text_error)
         if (allocated(s%error)) text = s%error%message
      case (text_header, text_summary)
         call need(s, session_solved, 'give its history header or summary', error)
         if (allocated(error)) return
         if (which == text_header) text = s%header
         if (which == text_summary) text = s%summary
      case (text_output_dir, text_output_name, text_history_path, text_summary_path, text_deck)
         if (.not. s%from_deck .or. s%state == state_empty) then
            call fatal_error(error, 'the session holds no deck: no output settings')
            return
         end if
         select case (which)
         case (text_output_dir)
            text = s%cfg%out%dir
         case (text_output_name)
            text = s%cfg%out%name
         case (text_history_path)
            call output_paths(s%cfg%out, hist, summ)
            text = hist
         case (text_summary_path)
            call output_paths(s%cfg%out, hist, summ)
            text = summ
         case default
            text = s%cfg%deck_path
         end select
      case default
         call fatal_error(error, 'no session text number '//trim(fmt_int(which)))
      end select
   end subroutine session_text

   !> Write the outputs into `dir` instead of the deck's &output dir.
   subroutine session_set_output_dir(s, dir, error)
      type(session_type), intent(inout) :: s              !! a session with a deck read
      character(len=*), intent(in) :: dir                 !! the output directory
      type(error_type), allocatable, intent(out) :: error !! no deck, or an empty name
      if (.not. s%from_deck .or. s%state == state_empty) then
         call fatal_error(error, 'the session holds no deck: no output settings')
         return
      end if
      if (len_trim(dir) == 0) then
         call fatal_error(error, 'the output directory is empty')
         return
      end if
      s%cfg%out%dir = dir
   end subroutine session_set_output_dir

   !> Write the history CSV (unless &output write_history = .false.) and the summary, as the
   !> executable does: the library's writer, into the &output dir (created when missing).
   subroutine session_write(s, error)
      type(session_type), intent(in) :: s                 !! a solved session read from a deck
      type(error_type), allocatable, intent(out) :: error !! not solved, or cannot write
      call need(s, session_solved, 'write its outputs', error)
      if (allocated(error)) return
      if (.not. s%from_deck) then
         call fatal_error(error, 'the session holds no deck: no output settings')
         return
      end if
      call write_outputs(s%cfg%out, s%cfg%model, s%res, s%cfg%deck_path, record=s%cfg%record, error=error)
      if (allocated(error)) error%message = s%cfg%deck_path//': '//error%message
   end subroutine session_write

   !> Write the history (when `history`) to `hist_path` and the summary to `summ_path` with the
   !> library's writer (each to a temporary name renamed when complete; nothing left on failure).
   subroutine session_write_files(s, hist_path, summ_path, history, error)
      type(session_type), intent(in) :: s                 !! a solved session
      character(len=*), intent(in) :: hist_path           !! the history CSV
      character(len=*), intent(in) :: summ_path           !! the summary file
      logical, intent(in) :: history                      !! write the history
      type(error_type), allocatable, intent(out) :: error !! not solved, or cannot write
      call need(s, session_solved, 'write its outputs', error)
      if (allocated(error)) return
      call write_output_files(hist_path, summ_path, history, s%header, s%res%hist, s%summary, error)
   end subroutine session_write_files

   ! ---------------------------------------------------------------- helpers
   subroutine reset(s)
      type(session_type), intent(inout) :: s
      type(session_type) :: fresh
      s = fresh
   end subroutine reset

   subroutine need(s, state, what, error)
      type(session_type), intent(in) :: s
      integer, intent(in) :: state
      character(len=*), intent(in) :: what
      type(error_type), allocatable, intent(out) :: error
      if (s%state == state) return
      select case (s%state)
      case (state_empty)
         call fatal_error(error, 'cannot '//what//': the session holds no deck')
      case (session_read)
         call fatal_error(error, 'cannot '//what//': the session is not solved')
      case (session_solved)
         call fatal_error(error, 'cannot '//what//': the session is already solved')
      case default
         call fatal_error(error, 'cannot '//what//': the solver failed')
      end select
   end subroutine need

end module fd_session
