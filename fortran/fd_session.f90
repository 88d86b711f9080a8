!> A session: one deck read once, then solved, queried and written, all through one object
!> the caller owns. It is what the Python extension holds between calls (as an opaque handle),
!> so that the deck and its record are read exactly once per run and every buffer the caller
!> needs is sized here, from the deck and the result, never guessed.
!>
!> Life cycle: session_open (or session_open_text) reads and validates the deck, and asks its
!> technique whether it can integrate the model (fd_technique's check_technique); session_solve
!> runs it; session_text, session_shape and the result's history give what it produced;
!> session_write writes the outputs with the library's writer. session_adopt makes a solved
!> session from a history and texts given by the caller, to write them with the same writer.
!>
!> The run's control (fd_run_control) lives here too: between open and solve the caller may
!> choose the DOFs and devices the history keeps (session_select; session_shape then reports
!> the reduced history), ask for the history to be written to its output file as the run goes
!> (session_stream: memory then does not grow with the duration; session_write commits the
!> file), give a buffer of its own that the rows go to (session_solve's `buffer`: the history is
!> then held once, by the caller) and a progress callback. While a solve runs in one thread,
!> another may call session_cancel (the solver stops within a poll, ~10 ms, with an error of
!> stat_cancelled; a streamed file is removed) and session_progress (the time reached).
module fd_session
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t, c_intptr_t, c_long_long, c_ptr, c_loc, c_f_pointer
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int
   use frictiondyn, only: run_config, result_type, read_deck, read_deck_string, run_config_solve, &
                          shape_of, summary_json, history_header, output_paths, write_outputs, &
                          write_output_files, run_control, select_history
   use fd_run_control, only: progress_callback, control_reset
   use fd_history_stream, only: history_file_sink
   use fd_output, only: make_dir, temp_output_paths, remove_made_dirs
   use fd_tempfiles, only: temp_tag, remove_stale_temps
   use fd_excitation, only: excitation_record
   use fd_spectrum, only: response_spectrum
   use fd_technique, only: check_technique
   implicit none
   private

   public :: session_type, session_open, session_open_text, session_adopt, session_solve
   public :: session_shape, session_text, session_set_output_dir, session_write, session_write_files
   public :: session_new, session_from_handle, session_free, session_spectrum
   public :: session_select, session_stream, session_cancel, session_progress, session_set_progress
   public :: text_header, text_summary, text_output_dir, text_output_name, text_history_path, &
             text_summary_path, text_deck, text_error

   ! what a session holds
   integer, parameter :: state_empty = 0   !! nothing read (or the deck was rejected)
   integer, parameter, public :: session_read = 1    !! the deck is read, not solved
   integer, parameter, public :: session_solved = 2  !! the result is there
   integer, parameter :: state_failed = 3  !! the solver failed: nothing more to get

   ! The status of an entry point of the C layer (driver/frictiondyn/_core.f90), one for each
   ! kind of failure, and the texts a session gives (session_text). These lines are the one
   ! source of the numbers: driver/gen_codes.py writes them into the Python package
   ! (frictiondyn/_codes.py) when it is built.
   integer, parameter, public :: status_ok = 0         !! success
   integer, parameter, public :: status_input = 1      !! a bad deck or input
   integer, parameter, public :: status_solver = 2     !! the solver failed
   integer, parameter, public :: status_misuse = 3     !! wrong state, wrong buffer, no session
   integer, parameter, public :: status_output = 4     !! an output file cannot be written
   integer, parameter, public :: status_no_memory = 5  !! not enough memory (fd_error's stat_no_memory)
   integer, parameter, public :: status_cancelled = 6  !! the solve was cancelled (session_cancel)
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
      type(run_control) :: ctl                        !! history selection, destinations, stop
      logical :: stream = .false.                     !! write the history file as the run goes
      character(len=:), allocatable :: tag            !! suffix of its temporary name
      character(len=:), allocatable :: stream_tmp     !! its temporary name, once complete
      character(len=:), allocatable :: made_dir       !! outermost directory created for it
      logical :: have_history = .false.               !! res%hist holds the history
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
      if (associated(s)) then
         call discard_stream(s)   ! a streamed history never committed is removed
         deallocate (s)
      end if
   end subroutine session_free

   !> Read and validate a deck file into a fresh session.
   subroutine session_open(s, path, error)
      type(session_type), intent(inout) :: s              !! the session (any previous content is dropped)
      character(len=*), intent(in) :: path                !! deck file
      type(error_type), allocatable, intent(out) :: error !! bad or missing deck or record
      call reset(s)
      call read_deck(path, s%cfg, error)
      if (.not. allocated(error)) call opened(s, error)
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
      if (.not. allocated(error)) call opened(s, error)
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

   !> Run the session's deck; its header and summary are then available, and its history:
   !> in `buffer` when given (the caller's (ncol, nout) array, filled row by row; the session
   !> keeps none), else in the session (unless the session streams its history and `keep` is
   !> false). A streamed history is complete under its temporary name (session_write renames
   !> it); on failure or cancel it is removed.
   subroutine session_solve(s, error, buffer, keep)
      type(session_type), intent(inout), target :: s      !! a session with a deck read
      type(error_type), allocatable, intent(out) :: error !! wrong state, or the solver failed
      real(dp), intent(inout), target, optional :: buffer(:, :) !! where the rows go
      logical, intent(in), optional :: keep               !! hold the history in the session
                                                          !! (default: unless streamed)
      type(error_type), allocatable :: close_error
      character(len=:), allocatable :: htmp, stmp, hist, summ

      call need(s, session_read, 'solve', error)
      if (allocated(error)) return
      call control_reset(s%ctl)
      s%ctl%keep = .not. (s%stream .and. s%cfg%out%history)
      if (present(keep)) s%ctl%keep = keep
      if (present(buffer)) then
         s%ctl%buffer => buffer
         s%ctl%keep = .false.
      end if
      if (allocated(s%ctl%sink)) deallocate (s%ctl%sink)
      if (s%stream .and. s%cfg%out%history) then
         call make_dir(s%cfg%out%dir, error, s%made_dir)
         if (allocated(error)) then
            s%state = state_failed
            return
         end if
         ! unique while the session lives: the process, its machine and the session's address
         if (.not. allocated(s%tag)) call temp_tag(int(transfer(c_loc(s), 0_c_intptr_t), c_long_long), s%tag)
         call output_paths(s%cfg%out, hist, summ)
         call remove_stale_temps(hist)   ! those of killed writers of the name
         call remove_stale_temps(summ)
         call temp_output_paths(s%cfg%out, s%tag, htmp, stmp)
         call history_file_sink(htmp, s%ctl%sink)
      end if
      call run_config_solve(s%cfg, s%res, error, s%ctl)
      nullify (s%ctl%buffer)
      if (allocated(error)) then
         call discard_stream(s)
         s%state = state_failed
         error%message = s%cfg%deck_path//": "//error%message   ! as the executable says it
         return
      end if
      if (allocated(s%ctl%sink)) then
         call s%ctl%sink%finish(close_error)
         if (allocated(close_error)) then
            call discard_stream(s)
            call move_alloc(close_error, error)
            s%state = state_failed
            return
         end if
         s%stream_tmp = htmp
      end if
      s%have_history = s%ctl%keep
      call history_header(s%res, s%header)
      call summary_json(s%cfg%model, s%res, s%cfg%deck_path, s%summary, s%cfg%record, s%cfg%record2, &
                        s%cfg%record3)
      s%state = session_solved
   end subroutine session_solve

   !> Keep only these DOFs and devices in the history (ascending, 1-based); before solve.
   subroutine session_select(s, dofs, devices, error)
      type(session_type), intent(inout) :: s              !! a session with a deck read
      integer, intent(in) :: dofs(:)                      !! DOFs kept
      integer, intent(in) :: devices(:)                   !! devices kept
      type(error_type), allocatable, intent(out) :: error !! wrong state, a number out of range
      call need(s, session_read, 'select the history', error)
      if (allocated(error)) return
      call select_history(s%ctl, dofs, devices, s%cfg%model%n_dof, s%cfg%model%n_devices, error)
   end subroutine session_select

   !> Write the history to its output file (the &output dir and name, or the directory set
   !> by session_set_output_dir) as the run goes, under the temporary name of
   !> temp_output_paths for `tag`; session_write commits it. Before solve.
   subroutine session_stream(s, error, tag)
      type(session_type), intent(inout) :: s              !! a session with a deck read
      type(error_type), allocatable, intent(out) :: error !! wrong state
      character(len=*), intent(in), optional :: tag       !! suffix of the temporary names
                                                          !! (temp_output_paths; default: the
                                                          !! process id and the session's address)
      call need(s, session_read, 'stream its history', error)
      if (allocated(error)) return
      s%stream = .true.
      if (present(tag)) s%tag = tag
   end subroutine session_stream

   !> Ask a running solve to stop (from another thread; harmless at any other time: the next
   !> solve clears the request).
   subroutine session_cancel(s)
      type(session_type), intent(inout) :: s   !! the session
      s%ctl%cancel = 1
   end subroutine session_cancel

   !> The time a running solve has reached, and the duration of the run [s].
   subroutine session_progress(s, t, duration)
      type(session_type), intent(in) :: s      !! the session
      real(dp), intent(out) :: t               !! time reached [s]
      real(dp), intent(out) :: duration        !! duration [s]
      t = s%ctl%time
      duration = s%ctl%duration
   end subroutine session_progress

   !> A procedure the solve calls every `interval` seconds of wall clock with the time reached.
   subroutine session_set_progress(s, callback, interval)
      type(session_type), intent(inout) :: s   !! the session
      procedure(progress_callback) :: callback !! the callback
      real(dp), intent(in) :: interval         !! seconds between calls
      s%ctl%on_progress => callback
      s%ctl%progress_interval = interval
   end subroutine session_set_progress

   !> The elastic response spectrum of the deck's recorded table motion (as read: units,
   !> scale; over the analysed duration): fd_spectrum's peaks for each period.
   subroutine session_spectrum(s, periods, xi, sd, psv, psa, sa, error)
      type(session_type), intent(in) :: s                 !! an open session
      real(dp), intent(in) :: periods(:)                  !! periods [s], >= 0
      real(dp), intent(in) :: xi                          !! damping ratio, 0 <= xi < 1
      real(dp), intent(out) :: sd(:)                      !! peak relative displacement [m]
      real(dp), intent(out) :: psv(:)                     !! pseudo-velocity [m/s]
      real(dp), intent(out) :: psa(:)                     !! pseudo-acceleration [m/s2]
      real(dp), intent(out) :: sa(:)                      !! peak absolute acceleration [m/s2]
      type(error_type), allocatable, intent(out) :: error !! no record, bad input
      integer :: n

      sd = 0.0_dp; psv = 0.0_dp; psa = 0.0_dp; sa = 0.0_dp
      if (s%state /= session_read .and. s%state /= session_solved .and. s%state /= state_failed) then
         call fatal_error(error, 'the session holds no deck')
         return
      end if
      associate (exc => s%cfg%exc)
         if (exc%kind /= excitation_record) then
            call fatal_error(error, "group &excitation: the response spectrum is of a recorded motion; "// &
                             "this deck's table motion is not a record")
            return
         end if
         n = min(size(exc%acc), nint(exc%duration/exc%dt_record) + 1)
         call response_spectrum(exc%acc(1:n), exc%dt_record, periods, xi, sd, psv, psa, sa, error)
      end associate
   end subroutine session_spectrum

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
         if (s%ctl%select_all) then
            call shape_of(s%cfg, ncol, nout)
         else
            call shape_of(s%cfg, ncol, nout, size(s%ctl%dofs), size(s%ctl%devices))
         end if
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
   !> executable does: the library's writer, into the &output dir (created when missing). A
   !> streamed history is renamed into place; else the history is the session's, or `data`
   !> (the caller's buffer of session_solve).
   subroutine session_write(s, error, data)
      type(session_type), intent(inout) :: s              !! a solved session read from a deck
      type(error_type), allocatable, intent(out) :: error !! not solved, or cannot write
      real(dp), intent(in), optional :: data(:, :)        !! the history, when the caller holds it
      character(len=:), allocatable :: hist, summ
      real(dp) :: none(s%res%ncol, 0)

      call need(s, session_solved, 'write its outputs', error)
      if (allocated(error)) return
      if (.not. s%from_deck) then
         call fatal_error(error, 'the session holds no deck: no output settings')
         return
      end if
      call output_paths(s%cfg%out, hist, summ)
      if (allocated(s%stream_tmp)) then
         ! the history is complete under its temporary name: commit it with the summary
         call write_output_files(hist, summ, s%cfg%out%history, s%header, none, s%summary, error, &
                                 tag=s%tag, streamed=.true.)
         if (allocated(s%ctl%sink)) deallocate (s%ctl%sink)   ! committed: not to be discarded
         deallocate (s%stream_tmp)
         if (allocated(error) .and. allocated(s%made_dir)) call remove_made_dirs(s%cfg%out%dir, s%made_dir)
         if (allocated(s%made_dir)) deallocate (s%made_dir)
      else
         call make_dir(s%cfg%out%dir, error)
         if (allocated(error)) return
         if (present(data)) then
            call write_output_files(hist, summ, s%cfg%out%history, s%header, data, s%summary, error)
         else if (s%have_history .or. .not. s%cfg%out%history) then
            call write_output_files(hist, summ, s%cfg%out%history, s%header, s%res%hist, s%summary, error)
         else
            call fatal_error(error, 'cannot write the history: the session does not hold it (give the buffer)')
         end if
      end if
      if (allocated(error)) error%message = s%cfg%deck_path//': '//error%message
   end subroutine session_write

   !> Write the history (when `history`) to `hist_path` and the summary to `summ_path` with the
   !> library's writer (each to a temporary name renamed when complete; nothing left on failure).
   !> The history is the session's, or `data` when given.
   subroutine session_write_files(s, hist_path, summ_path, history, error, data)
      type(session_type), intent(in) :: s                 !! a solved session
      character(len=*), intent(in) :: hist_path           !! the history CSV
      character(len=*), intent(in) :: summ_path           !! the summary file
      logical, intent(in) :: history                      !! write the history
      type(error_type), allocatable, intent(out) :: error !! not solved, or cannot write
      real(dp), intent(in), optional :: data(:, :)        !! the history, when the caller holds it
      call need(s, session_solved, 'write its outputs', error)
      if (allocated(error)) return
      if (present(data)) then
         call write_output_files(hist_path, summ_path, history, s%header, data, s%summary, error)
      else
         call write_output_files(hist_path, summ_path, history, s%header, s%res%hist, s%summary, error)
      end if
   end subroutine session_write_files

   ! ---------------------------------------------------------------- helpers
   !> The history columns the deck's &output selects (history_dofs, history_devices).
   subroutine deck_selection(s, error)
      type(session_type), intent(inout) :: s
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: dofs(:), devices(:)
      integer :: i

      if (.not. (allocated(s%cfg%out%history_dofs) .or. allocated(s%cfg%out%history_devices))) return
      if (allocated(s%cfg%out%history_dofs)) then
         dofs = s%cfg%out%history_dofs
      else
         dofs = [(i, i=1, s%cfg%model%n_dof)]
      end if
      if (allocated(s%cfg%out%history_devices)) then
         devices = s%cfg%out%history_devices
      else
         devices = [(i, i=1, s%cfg%model%n_devices)]
      end if
      call select_history(s%ctl, dofs, devices, s%cfg%model%n_dof, s%cfg%model%n_devices, error)
   end subroutine deck_selection

   !> A deck just read: ask its technique whether it can integrate the model and the table
   !> motion (fd_technique's check_technique; an error prefixed with the deck as the reader's
   !> are), take the deck's history selection, and hold the deck.
   subroutine opened(s, error)
      type(session_type), intent(inout) :: s
      type(error_type), allocatable, intent(out) :: error
      call check_technique(s%cfg%model, s%cfg%exc, s%cfg%opts, error)
      if (allocated(error)) then
         error%message = s%cfg%deck_path//", "//error%message
         return
      end if
      call deck_selection(s, error)
      if (allocated(error)) return
      s%state = session_read
      s%from_deck = .true.
   end subroutine opened

   subroutine reset(s)
      type(session_type), intent(inout) :: s
      type(session_type) :: fresh
      call discard_stream(s)
      s = fresh
   end subroutine reset

   !> Remove a streamed history not committed, and the directories created for it when
   !> they are left empty: a run that failed or was cancelled leaves nothing behind.
   subroutine discard_stream(s)
      type(session_type), intent(inout) :: s
      if (allocated(s%ctl%sink)) then
         call s%ctl%sink%discard()
         deallocate (s%ctl%sink)
      end if
      if (allocated(s%made_dir)) then
         call remove_made_dirs(s%cfg%out%dir, s%made_dir)
         deallocate (s%made_dir)
      end if
   end subroutine discard_stream

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
