!> frictiondyn: run one namelist deck and write its time history and summary.
!>
!>   frictiondyn DECK.nml
!>   frictiondyn --list DECKS.txt --index I    (deck I, 0-based, of a list: a job-array task)
!>   frictiondyn --version | --help
!>
!> Exit status: 0 success (also with correctness warnings), 1 error, 2 wrong command line;
!> killed by SIGINT/SIGTERM/SIGHUP/SIGXCPU: the temporary outputs are removed first.
!>
!> The history is written as the run goes, to its temporary name (renamed with the summary
!> when the run is complete): memory does not grow with the duration. On a terminal a
!> progress line is shown on standard error.
program frictiondyn_main
   use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_long_long, c_null_char
   use fd_kinds, only: dp
   use frictiondyn, only: error_type, output_paths, temp_output_paths
   use fd_session, only: session_type, session_open, session_stream, session_solve, session_write, &
                         session_set_progress
   use fd_progress_line, only: progress_wanted, progress_show, progress_clear
   use fd_version, only: frictiondyn_version
   use fd_warnings, only: warning_text, run_warnings
   use fd_tempfiles, only: temp_tag
   use fd_error, only: fmt_text
   use fd_textio, only: line_type, read_file_text, split_lines, cr_line_ends
   use fd_undefined, only: undefined_why
   use fd_statistics, only: technique_counts, technique_setup
   use fd_result, only: result_type
   use fd_matrices, only: modes_type, modes_flexible, modes_rigid, modes_unrestrained
   implicit none

   interface
      subroutine install_signal_handlers() bind(c, name='fd_app_install_signal_handlers')
      end subroutine install_signal_handlers
      function register_temps(a, b) bind(c, name='fd_app_register_temps') result(stat)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: a(*), b(*)
         integer(c_int) :: stat
      end function register_temps
      subroutine clear_temps() bind(c, name='fd_app_clear_temps')
      end subroutine clear_temps
   end interface

   type(session_type), target :: ses
   type(error_type), allocatable :: error
   character(len=:), allocatable :: deck, list, index_text, arg, hist, summ, htmp, stmp, tag
   type(warning_text), allocatable :: warns(:)
   integer :: nargs, i, idx, ios
   interface
      !> C's exit: ends the program with a status and no message (Fortran 2008 has no
      !> silent STOP with a code; STOP's QUIET= is Fortran 2018).
      subroutine c_exit(status) bind(c, name='exit')
         import :: c_int
         integer(c_int), value :: status
      end subroutine c_exit
   end interface

   call install_signal_handlers()
   nargs = command_argument_count()
   if (nargs == 0) call usage_error('no deck given')
   i = 1
   do while (i <= nargs)
      call argument(i, arg)
      select case (arg)
      case ('-h', '--help')
         call help()
         stop
      case ('-V', '--version')
         write (output_unit, '(a)') 'frictiondyn '//frictiondyn_version
         stop
      case ('--list')
         if (i == nargs) call usage_error('--list needs a file of decks')
         i = i + 1
         call argument(i, list)
      case ('--index')
         if (i == nargs) call usage_error('--index needs a number')
         i = i + 1
         call argument(i, index_text)
      case default
         if (arg(1:min(1, len(arg))) == '-' .and. len(arg) > 1) call usage_error("unknown option '"//trim(fmt_text(arg))//"'")
         if (allocated(deck)) call usage_error('one deck at a time (use --list for many)')
         deck = arg
      end select
      i = i + 1
   end do
   if (allocated(list) .neqv. allocated(index_text)) call usage_error('--list and --index go together')
   if (allocated(list) .and. allocated(deck)) call usage_error('give a deck or --list/--index, not both')
   if (allocated(list)) then
      if (verify(index_text, '0123456789') /= 0 .or. len(index_text) == 0 .or. len(index_text) > 9) &
         call usage_error("--index '"//trim(fmt_text(index_text))//"' is not a whole number >= 0")
      read (index_text, *, iostat=ios) idx
      call deck_of_list(list, idx, deck, error)
      if (allocated(error)) call fail(error%message)
   end if
   if (.not. allocated(deck)) call usage_error('no deck given')

   call session_open(ses, deck, error)
   if (allocated(error)) call fail(error%message)

   ! the temporary outputs, registered for the signal handler before they exist: the history
   ! is written under its temporary name as the run goes, and committed with the summary
   call temp_tag(0_c_long_long, tag)
   call temp_output_paths(ses%cfg%out, tag, htmp, stmp)
   if (register_temps(htmp//c_null_char, stmp//c_null_char) /= 0) &
      call fail(deck//": output path too long: '"//htmp//"'")
   if (progress_wanted()) call session_set_progress(ses, progress_show, 0.2_dp)
   call session_stream(ses, error, tag)
   if (allocated(error)) call fail(deck//": "//error%message)
   call session_solve(ses, error, keep=.false.)   ! the history goes to its file or nowhere: none in memory
   call progress_clear()
   if (allocated(error)) then
      call clear_temps()
      call fail(error%message)   ! the session names the deck
   end if
   call session_write(ses, error)
   call clear_temps()
   if (allocated(error)) call fail(error%message)

   associate (res => ses%res, cfg => ses%cfg, &
              n => technique_counts(ses%res%newmark, ses%res%exact, ses%res%moreau_jean), &
              setup => technique_setup(ses%res%newmark, ses%res%exact, ses%res%moreau_jean))
   ! the warnings the result calls for (fd_warnings: the summary holds the same texts)
   call run_warnings(res, warns)
   do i = 1, size(warns)
      write (error_unit, '(a)') 'frictiondyn: warning: '//warns(i)%text
   end do
   deallocate (warns)
   write (output_unit, '(a)') 'frictiondyn: '//deck
   ! an undefined value is said to be so (fd_undefined), never printed as 0
   if (len_trim(undefined_why(res, 'period_stuck_s')) > 0) then
      write (output_unit, '(a,i0,a,i0,a,i0,a,i0)') '  rigid-link period not defined ('// &
         trim(undefined_why(res, 'period_stuck_s'))//'); steps dt1 ', &
         n%steps_dt1, ', nested ', n%steps_nested, ', dt2 ', n%steps_dt2, ', finer ', n%steps_finer
   else
      write (output_unit, '(a,i0,a,i0,a,i0,a,i0)') '  rigid-link period '//trim(num(setup%period_stuck))//' s; steps dt1 ', &
         n%steps_dt1, ', nested ', n%steps_nested, ', dt2 ', n%steps_dt2, ', finer ', n%steps_finer
   end if
   call print_periods(res)
   if (n%steps_implicit + n%implicit_fallbacks > 0) &
      write (output_unit, '(a,i0,a,i0,a,i0,a)') '  implicit phases: ', n%steps_implicit, ' dt1 steps settled (', &
      n%implicit_redos, ' trials redone), ', n%implicit_fallbacks, ' refined as the paper''s'
   if (allocated(cfg%record%path)) then
      write (output_unit, '(a,i0,a,es12.5,a)') '  record '//cfg%record%path//' ('//trim(cfg%record%format)// &
         trim(merge(', detected', '          ', cfg%record%detected))//', '//trim(cfg%record%units)//'): ', &
         cfg%record%npts, ' samples, dt ', cfg%record%dt, ' s'
   end if
   do i = 1, res%n_devices
      write (output_unit, '(a,i0,a,i0,a,i0,a)') '  device ', i, ': stick->slip ', res%stick_to_slip(i), &
         ', slip->stick ', res%slip_to_stick(i), ', dissipated '//trim(num(res%dissipated(i)))//' J, slip travel '// &
         trim(num(res%slip_travel(i)))//' m'
   end do
   do i = 1, res%n_dof
      write (output_unit, '(a,i0,a,es12.5,a,es12.5,a)') '  dof ', i, ': peak |u| ', res%peak_u(i), &
         ' m, peak |a_abs| ', res%peak_aabs(i), ' m/s2'
   end do
   call print_storeys(res)
   write (output_unit, '(a,i0)') '  correctness violations: ', res%violations
   call output_paths(cfg%out, hist, summ)
   if (cfg%out%history) write (output_unit, '(a)') '  history: '//hist
   write (output_unit, '(a)') '  summary: '//summ
   end associate
   ! a main program's variables are not deallocated when it ends: free them, so that the
   ! leak checker of the checked build (tools/test_checked.sh) finds nothing
   if (allocated(deck)) deallocate (deck)
   if (allocated(arg)) deallocate (arg)
   if (allocated(hist)) deallocate (hist)
   if (allocated(summ)) deallocate (summ)
   if (allocated(htmp)) deallocate (htmp)
   if (allocated(stmp)) deallocate (stmp)
   if (allocated(tag)) deallocate (tag)
   if (allocated(list)) deallocate (list)
   if (allocated(index_text)) deallocate (index_text)

contains

   subroutine argument(k, val)
      integer, intent(in) :: k
      character(len=:), allocatable, intent(out) :: val
      integer :: length
      call get_command_argument(k, length=length)
      allocate (character(len=length) :: val)
      if (length > 0) call get_command_argument(k, val)
   end subroutine argument

   !> Line idx+1 of the list file: a deck path, relative to the list's directory unless
   !> it starts with '/'. The list is read as a deck is (fd_textio): a directory, a missing
   !> or unreadable file, and lines that end with CR alone are errors saying so.
   subroutine deck_of_list(path, idx, deck_path, error)
      character(len=*), intent(in) :: path
      integer, intent(in) :: idx
      character(len=:), allocatable, intent(out) :: deck_path
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text, line
      type(line_type), allocatable :: lines(:)
      integer :: stat, slash

      call read_file_text(path, text, error)
      if (allocated(error)) then
         error%message = "--list: "//error%message
         return
      end if
      if (len_trim(cr_line_ends(text)) > 0) then
         allocate (error)
         error%message = "--list '"//path//"'"//trim(cr_line_ends(text))
         return
      end if
      call split_lines(text, lines, stat)
      if (stat /= 0) then
         allocate (error)
         error%message = "--list '"//path//"': not enough memory for its lines"
         return
      end if
      if (idx >= size(lines)) then
         allocate (error)
         error%message = "--list '"//path//"' has only "//trim(itoa(size(lines)))//" line(s); --index "// &
                         trim(itoa(idx))//" asks for line "//trim(itoa(idx + 1))
         return
      end if
      line = lines(idx + 1)%s
      if (len_trim(line) == 0) then
         allocate (error)
         error%message = "--list '"//path//"', line "//trim(itoa(idx + 1))//" (--index "//trim(itoa(idx))// &
                         ") is empty: expected the path of a deck"
         return
      end if
      deck_path = trim(adjustl(line))
      if (deck_path(1:1) /= '/') then
         slash = index(path, '/', back=.true.)
         deck_path = path(1:slash)//deck_path
      end if
   end subroutine deck_of_list

   !> The first periods (at most three) of the stuck and the free system, on one line:
   !> "periods: stuck 0.2961, 0.007235 s; free 0.4790, 0.1857 s" (inf: a rigid-body mode;
   !> none: every mass held to the table); nothing when no modes were computed.
   subroutine print_periods(res)
      type(result_type), intent(in) :: res
      character(len=:), allocatable :: line

      line = ''
      call add_periods(line, 'stuck', res%eng%stuck)
      call add_periods(line, 'free', res%eng%free)
      if (len(line) > 0) write (output_unit, '(a)') '  periods:'//line
   end subroutine print_periods

   !> One system's part of print_periods' line.
   subroutine add_periods(line, name, m)
      character(len=:), allocatable, intent(inout) :: line
      character(len=*), intent(in) :: name
      type(modes_type), intent(in) :: m
      integer :: k

      if (m%status /= modes_flexible .and. m%status /= modes_rigid .and. m%status /= modes_unrestrained) return
      if (len(line) > 0) line = line//';'
      line = line//' '//name
      if (m%status == modes_rigid .or. m%n == 0) then
         line = line//' none (every mass held to the table)'
         return
      end if
      do k = 1, min(3, m%n)
         if (m%omega2(k) > 0.0_dp) then
            line = line//' '//trim(num(m%period(k)))
         else
            line = line//' inf'
         end if
         if (k < min(3, m%n)) line = line//','
      end do
      line = line//' s'
   end subroutine add_periods

   !> Per storey its peak drift (and drift ratio, when its height is given) and peak shear,
   !> then the peak base shear and its time.
   subroutine print_storeys(res)
      type(result_type), intent(in) :: res
      character(len=32) :: ratio
      integer :: i

      associate (eng => res%eng)
         do i = 1, eng%n_storeys
            ratio = ''
            if (eng%height(i) > 0.0_dp) ratio = ' ('//trim(num(100.0_dp*eng%peak_drift(i)/eng%height(i)))//' %)'
            write (output_unit, '(a)') '  '//trim(eng%storey_label(i))//': peak drift '//trim(num(eng%peak_drift(i)))// &
               ' m'//trim(ratio)//', peak shear '//trim(num(eng%peak_shear(i)))//' N'
         end do
         if (.not. allocated(eng%peak_shear)) return
         if (eng%peak_shear(0) > 0.0_dp) then
            write (output_unit, '(a)') '  base shear: peak '//trim(num(eng%peak_shear(0)))//' N at t = '// &
               trim(num(eng%peak_shear_time(0)))//' s'
         else
            write (output_unit, '(a)') '  base shear: peak 0 N'
         end if
      end associate
   end subroutine print_storeys

   !> x with four significant digits: fixed from 0.01 to 1e5 (0.2960, 20.00, 1234), else
   !> scientific (7.235E-03, 1.234E+06); 0 as 0.
   pure function num(x) result(s)
      use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
      real(dp), intent(in) :: x
      character(len=24) :: s
      character(len=16) :: fmt
      integer :: d, ios

      if (x == 0.0_dp) then
         s = '0'
         return
      end if
      if (ieee_is_finite(x) .and. abs(x) >= 0.01_dp .and. abs(x) < 1.0e5_dp) then
         d = max(0, 3 - floor(log10(abs(x))))
         write (fmt, '(a,i0,a)') '(f24.', d, ')'
      else
         fmt = '(es24.3)'
      end if
      write (s, fmt, iostat=ios) x
      if (ios /= 0) s = '?'
      s = adjustl(s)
      if (s(len_trim(s):len_trim(s)) == '.') s(len_trim(s):len_trim(s)) = ' '
      if (s(1:1) == '.') s = '0'//s
      if (s(1:2) == '-.') s = '-0'//s(2:)
   end function num

   pure function itoa(k) result(s)
      integer, intent(in) :: k
      character(len=16) :: s
      write (s, '(i0)') k
   end function itoa

   subroutine help()
      write (output_unit, '(a)') 'usage: frictiondyn DECK.nml', &
         '       frictiondyn --list DECKS.txt --index I', &
         '       frictiondyn --version | --help', '', &
         'Runs one namelist deck (docs/namelist.md) and writes <dir>/<name>.csv (time history)', &
         'and <dir>/<name>.summary.json (peaks, steps, transitions, energy) as one consistent pair.', &
         '', &
         '  DECK.nml             the deck to run', &
         '  --list DECKS.txt     a file with one deck path a line (relative to its directory)', &
         '  --index I            run the deck on line I+1 of the list (0-based, as', &
         '                       $SLURM_ARRAY_TASK_ID in a job array)', &
         '  -V, --version        print the version', &
         '  -h, --help           print this help', '', &
         'Exit status: 0 success (also with correctness warnings), 1 error (the message on', &
         'standard error names the file, group, variable and value), 2 wrong command line.', &
         'Batch runs: python -m frictiondyn sweep (docs/batch.md).'
   end subroutine help

   !> End the program with a non-zero exit status, silently, after flushing the output.
   subroutine quit(status)
      integer, intent(in) :: status  !! exit status
      flush (output_unit)
      flush (error_unit)
      call c_exit(int(status, c_int))
   end subroutine quit

   subroutine usage_error(msg)
      character(len=*), intent(in) :: msg
      write (error_unit, '(a)') 'frictiondyn: '//msg
      write (error_unit, '(a)') 'usage: frictiondyn DECK.nml | --list DECKS.txt --index I | --version | --help'
      call quit(2)
   end subroutine usage_error

   subroutine fail(msg)
      character(len=*), intent(in) :: msg
      write (error_unit, '(a)') 'frictiondyn: error: '//msg
      call quit(1)
   end subroutine fail

end program frictiondyn_main
