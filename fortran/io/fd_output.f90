!> Output files of a run: the time-history CSV (a header naming every column with its
!> unit, 17 significant digits) and the summary (JSON). Each is written to a temporary
!> name unique to the writer and the pair is committed under a lock (write_outputs); on
!> any error no output file is left behind and earlier outputs of the name stay.
module fd_output
   use, intrinsic :: iso_c_binding, only: c_int, c_long, c_long_long, c_null_char
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real
   use fd_model, only: model_type, output_type, law_name, technique_name
   use fd_result, only: result_type, record_system_names, history_header, run_setup, setup_of
   use fd_record, only: record_info
   use fd_warnings, only: warning_text, run_checks, n_checks
   use fd_check, only: check_type, check_warnings, outcome_of
   use fd_undefined, only: undefined_why
   use fd_version, only: frictiondyn_version
   use fd_history_stream, only: format_row, stream_value_width
   use fd_names, only: excitation_types, keyword_len, label_len
   use fd_matrices, only: modes_type, modes_flexible, modes_rigid, modes_unrestrained
   use fd_engineering, only: engineering_type
   use fd_statistics, only: newmark_stats, event_driven_stats, moreau_jean_stats, summary_counts, &
                            newmark_counts, event_driven_counts, moreau_jean_counts
   use fd_fileops, only: c_lock_acquire, c_lock_release, c_unlink, c_rename, os_error, &
                         c_file_create, c_file_write, c_file_close, c_mkdir, c_rmdir, lock_not_file
   use fd_tempfiles, only: temp_tag, remove_stale_temps
   implicit none
   private

   public :: output_type, write_outputs, write_output_files, output_paths, temp_output_paths, summary_json, &
             history_header, make_dir, remove_made_dirs

   integer(c_int), parameter :: enoent = 2, eexist = 17
   character(len=1), parameter :: nl = achar(10)   !! the summary's line end

   !> The summary's text as it grows (put appends, doubling the capacity when full).
   type :: json_text
      character(len=:), allocatable :: buf   !! capacity
      integer :: pos = 0                     !! characters used
   end type json_text

contains

   !> Paths of the time-history CSV and of the summary file.
   pure subroutine output_paths(out, hist, summ)
      type(output_type), intent(in) :: out                  !! output settings
      character(len=:), allocatable, intent(out) :: hist    !! the CSV file
      character(len=:), allocatable, intent(out) :: summ    !! the JSON file
      hist = out%dir//'/'//out%name//'.csv'
      summ = out%dir//'/'//out%name//'.summary.json'
   end subroutine output_paths

   !> Temporary names of the two outputs for a tag unique to the writing process:
   !> `<dir>/.<name>.csv.<tag>.tmp` and `<dir>/.<name>.summary.json.<tag>.tmp`.
   pure subroutine temp_output_paths(out, tag, hist_tmp, summ_tmp)
      type(output_type), intent(in) :: out                    !! output settings
      character(len=*), intent(in) :: tag                     !! unique per writer
      character(len=:), allocatable, intent(out) :: hist_tmp  !! temporary CSV
      character(len=:), allocatable, intent(out) :: summ_tmp  !! temporary summary
      character(len=:), allocatable :: hist, summ
      call output_paths(out, hist, summ)
      call hidden_name(hist, '.'//tag//'.tmp', hist_tmp)
      call hidden_name(summ, '.'//tag//'.tmp', summ_tmp)
   end subroutine temp_output_paths

   !> `dir/.file<suffix>` for a path `dir/file` (hidden, in the same directory, so that a
   !> rename onto the path never crosses file systems).
   pure subroutine hidden_name(path, suffix, hidden)
      character(len=*), intent(in) :: path                  !! a file path
      character(len=*), intent(in) :: suffix                !! appended to the name
      character(len=:), allocatable, intent(out) :: hidden  !! the hidden name
      integer :: slash
      slash = index(path, '/', back=.true.)
      hidden = path(1:slash)//'.'//path(slash + 1:)//suffix
   end subroutine hidden_name

   !> A tag for temporary names: the process, its machine and a random number (temp_tag; the
   !> names are also created exclusively, so two writers never share one).
   subroutine default_tag(tag)
      character(len=:), allocatable, intent(out) :: tag  !! e.g. '12345_node07_3f9a0c1d'
      real(dp) :: r
      call random_number(r)
      call temp_tag(int(r*2147483647.0_dp, c_long_long), tag)
   end subroutine default_tag

   !> Write the history (when out%history) and the summary of a run into out%dir (created
   !> when missing) as one consistent pair: see write_output_files.
   subroutine write_outputs(out, model, res, deck_path, record, tag, error)
      type(output_type), intent(in) :: out                !! output settings
      type(model_type), intent(in) :: model               !! the model run
      type(result_type), intent(in) :: res                !! its result
      character(len=*), intent(in) :: deck_path           !! deck, named in the summary
      type(record_info), intent(in), optional :: record   !! the record read, named in the summary
      character(len=*), intent(in), optional :: tag       !! unique suffix of the temporary names
      type(error_type), allocatable, intent(out) :: error !! cannot create, write or rename a file
      character(len=:), allocatable :: hist, summ, header, js

      call make_dir(out%dir, error)
      if (allocated(error)) return
      call output_paths(out, hist, summ)
      call history_header(res, header)
      call summary_json(model, res, deck_path, js, record)
      call write_output_files(hist, summ, out%history, header, res%hist, js, error, tag)
   end subroutine write_outputs

   !> The one writer of output files (the executable's and the Python package's): a history
   !> (when `history`: its header line, then one row per sample) at `hist_path` and a
   !> summary text at `summ_path`, as one consistent pair. Each goes to a hidden temporary
   !> name in its directory, unique to the writer (`tag`, default: process id and a random
   !> number); when both are complete they are committed under an exclusive lock on
   !> `<dir>/.<name>.lock` (name: the summary's without `.summary.json`): remove the old
   !> summary, rename the CSV, rename the summary. Two writers of one name thus commit one
   !> after the other, and a writer killed in the middle leaves a CSV without summary (an
   !> incomplete run), never one run's CSV beside another's summary. A failed write (full
   !> disk, quota) removes the temporary files and leaves the earlier outputs untouched; the
   !> error names the file.
   !>
   !> A history written as the run went (fd_history_stream, under the temporary name
   !> temp_output_paths gives for `tag`) is committed the same way: `streamed` says it is
   !> complete at that name, and `data` is not used; when `history` is false it is removed.
   subroutine write_output_files(hist_path, summ_path, history, header, data, summary, error, tag, streamed)
      character(len=*), intent(in) :: hist_path           !! the history CSV
      character(len=*), intent(in) :: summ_path           !! the summary file
      logical, intent(in) :: history                      !! write the history
      character(len=*), intent(in) :: header              !! 'name[unit],...' of each column
      real(dp), intent(in) :: data(:, :)                  !! history (columns, samples)
      character(len=*), intent(in) :: summary             !! summary text (JSON)
      type(error_type), allocatable, intent(out) :: error !! cannot create, write or rename a file
      character(len=*), intent(in), optional :: tag       !! unique suffix of the temporary names
      logical, intent(in), optional :: streamed           !! the history is complete under its
                                                          !! temporary name (needs `tag`)
      character(len=:), allocatable :: htmp, stmp, mytag, lock, stem
      integer(c_int) :: err, fd
      integer :: attempt, ls
      logical :: have

      have = .false.
      if (present(streamed)) have = streamed .and. present(tag)
      call remove_stale_temps(hist_path)   ! those of killed writers of the name
      call remove_stale_temps(summ_path)
      do attempt = 1, 10
         if (present(tag)) then
            mytag = tag
         else
            call default_tag(mytag)
         end if
         call hidden_name(hist_path, '.'//mytag//'.tmp', htmp)
         call hidden_name(summ_path, '.'//mytag//'.tmp', stmp)
         call write_summary(stmp, summary, error)
         if (.not. allocated(error)) exit
         if (present(tag) .or. error%stat /= eexist) then  ! the name exists (random clash)
            if (have) err = c_unlink(htmp//c_null_char)
            return
         end if
      end do
      if (allocated(error)) return
      if (have .and. .not. history) then
         err = c_unlink(htmp//c_null_char)
      else if (history .and. .not. have) then
         call write_history(htmp, header, data, error)
         if (allocated(error)) then
            err = c_unlink(stmp//c_null_char)
            return
         end if
      end if

      stem = summ_path
      ls = len(stem) - len('.summary.json')
      if (ls > 0) then
         if (stem(ls + 1:) == '.summary.json') stem = stem(1:ls)
      end if
      call hidden_name(stem, '.lock', lock)
      err = c_lock_acquire(lock//c_null_char, fd)
      if (err == lock_not_file) then
         call discard()
         call fatal_error(error, "cannot lock '"//lock//"': it is a symbolic link or not a regular file "// &
                          "(a lock file is never followed; remove it)")
         return
      else if (err /= 0) then
         call discard()
         call os_error(error, "cannot lock '"//lock//"'", err)
         return
      end if
      ! the commit: the summary marks a complete pair, so it goes first and comes back last
      err = c_unlink(summ_path//c_null_char)
      if (err /= 0 .and. err /= enoent) then
         call discard()
         call os_error(error, "cannot replace '"//summ_path//"'", err)
      else if (history) then
         err = c_rename(htmp//c_null_char, hist_path//c_null_char)
         if (err /= 0) then
            call discard()
            call os_error(error, "cannot rename '"//htmp//"' to '"//hist_path//"'", err)
         end if
      else
         ! no history this time: an older CSV of the name would not match the new summary
         err = c_unlink(hist_path//c_null_char)
         if (err /= 0 .and. err /= enoent) then
            call discard()
            call os_error(error, "cannot remove the earlier '"//hist_path//"'", err)
         end if
      end if
      if (.not. allocated(error)) then
         err = c_rename(stmp//c_null_char, summ_path//c_null_char)
         if (err /= 0) then
            call discard()
            call os_error(error, "cannot rename '"//stmp//"' to '"//summ_path//"'", err)
         end if
      end if
      err = c_lock_release(lock//c_null_char, fd)
   contains
      subroutine discard()
         integer(c_int) :: e
         e = c_unlink(stmp//c_null_char)
         if (history) e = c_unlink(htmp//c_null_char)
      end subroutine discard
   end subroutine write_output_files

   !> Create a directory and its missing parents; `made`, when given, is the first (outermost)
   !> directory this call created (not allocated: none), for remove_made_dirs.
   subroutine make_dir(dir, error, made)
      character(len=*), intent(in) :: dir
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable, intent(out), optional :: made
      integer :: i
      integer(c_int) :: err, first
      logical :: exists

      first = 0
      do i = 2, len(dir) + 1
         if (i <= len(dir)) then
            if (dir(i:i) /= '/') cycle
         end if
         inquire (file=dir(1:i - 1)//'/.', exist=exists)
         if (exists) cycle
         err = c_mkdir(dir(1:i - 1)//c_null_char)
         if (err == 0 .and. present(made)) then
            if (.not. allocated(made)) made = dir(1:i - 1)
         else if (err /= 0 .and. err /= eexist .and. first == 0) then
            first = err
         end if
      end do
      inquire (file=dir//'/.', exist=exists)
      if (exists) return
      if (first /= 0) then
         call os_error(error, "&output: cannot create the output directory dir = '"//dir//"'", first)
      else
         call fatal_error(error, "&output: cannot create the output directory dir = '"//dir//"'")
      end if
   end subroutine make_dir

   !> Remove the directories make_dir created for `dir` (`made` the outermost), innermost
   !> first, each only when empty (rmdir): a run that failed leaves no directory behind.
   subroutine remove_made_dirs(dir, made)
      character(len=*), intent(in) :: dir   !! the directory asked for
      character(len=*), intent(in) :: made  !! the outermost one created
      integer :: i, stat

      if (len(made) == 0 .or. len(made) > len(dir)) return
      if (dir(1:len(made)) /= made) return
      i = len(dir)
      do while (i >= len(made))
         if (i == len(dir) .or. dir(i + 1:i + 1) == '/') then
            stat = c_rmdir(dir(1:i)//c_null_char)
            if (stat /= 0) return
         end if
         i = i - 1
      end do
   end subroutine remove_made_dirs

   !> Create a new file (exclusively: error stat 17 when the name exists) for writing.
   subroutine create_new(path, fd, error)
      character(len=*), intent(in) :: path
      integer(c_int), intent(out) :: fd
      type(error_type), allocatable, intent(out) :: error
      integer(c_int) :: err
      err = c_file_create(path//c_null_char, fd)
      if (err /= 0) then
         call os_error(error, "cannot create '"//path//"'", err)
         if (err == eexist) error%stat = 17
      end if
   end subroutine create_new

   !> Write bytes; on failure the file is closed and removed, and the error names it.
   subroutine put_bytes(fd, path, text, error)
      integer(c_int), intent(in) :: fd
      character(len=*), intent(in) :: path, text
      type(error_type), allocatable, intent(out) :: error
      integer(c_int) :: err, e
      if (len(text) == 0) return
      err = c_file_write(fd, text, int(len(text), c_long))
      if (err /= 0) then
         e = c_file_close(fd)
         e = c_unlink(path//c_null_char)
         call os_error(error, "cannot write '"//path//"'", err)
      end if
   end subroutine put_bytes

   !> Flush to disk and close; on failure (a full disk or quota may show only here) the
   !> file is removed and the error names it.
   subroutine finish(fd, path, error)
      integer(c_int), intent(in) :: fd
      character(len=*), intent(in) :: path
      type(error_type), allocatable, intent(out) :: error
      integer(c_int) :: err, e
      err = c_file_close(fd)
      if (err /= 0) then
         e = c_unlink(path//c_null_char)
         call os_error(error, "cannot write '"//path//"'", err)
      end if
   end subroutine finish

   !> The history CSV: rows formatted into a buffer of about 1 MB, written with POSIX
   !> write (every error is seen: gfortran's own writes lose a full disk).
   subroutine write_history(path, header, data, error)
      character(len=*), intent(in) :: path
      character(len=*), intent(in) :: header
      real(dp), intent(in) :: data(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer(c_int) :: fd
      integer :: i, pos, width, rows_per_chunk
      character(len=:), allocatable :: fmt, buf

      call create_new(path, fd, error)
      if (allocated(error)) return
      call put_bytes(fd, path, header//nl, error)
      if (allocated(error)) return
      fmt = '('//trim(fmt_int(size(data, 1)))//'(es24.16e3,:,","))'
      width = 25*size(data, 1)               ! 24 characters a value, a comma or the newline
      rows_per_chunk = max(1, 1048576/width)
      allocate (character(len=width*rows_per_chunk) :: buf)
      pos = 0
      do i = 1, size(data, 2)
         write (buf(pos + 1:pos + width - 1), fmt) data(:, i)
         buf(pos + width:pos + width) = nl
         pos = pos + width
         if (pos == len(buf) .or. i == size(data, 2)) then
            call put_bytes(fd, path, buf(1:pos), error)
            if (allocated(error)) return
            pos = 0
         end if
      end do
      call finish(fd, path, error)
   end subroutine write_history

   subroutine write_summary(path, js, error)
      character(len=*), intent(in) :: path
      character(len=*), intent(in) :: js
      type(error_type), allocatable, intent(out) :: error
      integer(c_int) :: fd

      call create_new(path, fd, error)
      if (allocated(error)) return
      call put_bytes(fd, path, js//achar(10), error)
      if (allocated(error)) return
      call finish(fd, path, error)
   end subroutine write_summary

   !> The summary of a run as a JSON object (keys documented in docs/namelist.md): its parts in
   !> order, each written by its own routine (the run and its model, each check of the step,
   !> the peaks and phase changes, the technique's statistics, the checks of the run, the
   !> energy balance, the engineering outputs, the warnings). Every verdict is its check
   !> record's (fd_warnings' run_checks), the steps and the stuck mode the technique's set-up.
   subroutine summary_json(model, res, deck_path, js, record, record2, record3)
      type(model_type), intent(in) :: model                !! the model run
      type(result_type), intent(in) :: res                 !! its result
      character(len=*), intent(in) :: deck_path            !! deck named in the summary
      character(len=:), allocatable, intent(out) :: js     !! the JSON text
      type(record_info), intent(in), optional :: record    !! the record read, if any
      type(record_info), intent(in), optional :: record2   !! the second component's record, if any
      type(record_info), intent(in), optional :: record3   !! the vertical component's record, if any
      type(json_text) :: jt
      type(check_type) :: checks(n_checks)

      call run_checks(res, checks)
      allocate (character(len=4096 + 64*(res%n_dof + res%n_devices)*8) :: jt%buf)
      call put(jt, '{'//nl)
      call run_part(jt, deck_path, record, record2, record3)
      call model_part(jt, model, res)
      call mode_part(jt, res, outcome_of(checks, 'mode_resolution'))
      call harmonic_part(jt, res%harmonic_error, outcome_of(checks, 'harmonic_resolution'))
      call record_step_part(jt, res, outcome_of(checks, 'record_resolution'))
      call stick_part(jt, res%stick_freq_error, res%stick_ringing_ratio, res%stick_ringing, res%stick_margin, &
                      outcome_of(checks, 'stick_resolution'))
      call band_part(jt, res%band_x, res%band_alternation, res%band_alternation_time, &
                     outcome_of(checks, 'band_resolution'))
      call peaks_part(jt, res)
      if (res%n_bearings > 0) call bearings_part(jt, model, res)
      call statistics_part(jt, res)
      call correctness_part(jt, res)
      call mu_part(jt, res)
      call energy_part(jt, res, outcome_of(checks, 'energy_balance'))
      call plausibility_part(jt, checks)
      call engineering_part(jt, model, res)
      call kint(jt, 'samples', res%nout)
      call warnings_part(jt, checks)
      call put(jt, '  "run_time_s": '//trim(json_real(res%run_time))//nl//'}')
      js = jt%buf(1:jt%pos)
   end subroutine summary_json

   !> The deck, the program's version and the records read (if any).
   subroutine run_part(jt, deck_path, record, record2, record3)
      type(json_text), intent(inout) :: jt                 !! the summary
      character(len=*), intent(in) :: deck_path            !! deck named in the summary
      type(record_info), intent(in), optional :: record    !! the record read, if any
      type(record_info), intent(in), optional :: record2   !! the second component's, if any
      type(record_info), intent(in), optional :: record3   !! the vertical component's, if any
      character(len=:), allocatable :: esc

      call json_escape(deck_path, esc)
      call put(jt, '  "deck": "'//esc//'",'//nl)
      call put(jt, '  "frictiondyn_version": "'//frictiondyn_version//'",'//nl)
      if (present(record)) call record_item(jt, 'record', record)
      if (present(record2)) call record_item(jt, 'record2', record2)
      if (present(record3)) call record_item(jt, 'record3', record3)
   end subroutine run_part

   !> A record read: its file, format, units, samples, step, scale, peak and hash.
   subroutine record_item(jt, key, record)
      type(json_text), intent(inout) :: jt                 !! the summary
      character(len=*), intent(in) :: key                  !! its key
      type(record_info), intent(in) :: record              !! the record
      character(len=:), allocatable :: esc

      if (.not. allocated(record%path)) return
      call put(jt, '  "'//key//'": {')
      call json_escape(record%path, esc)
      call put(jt, '"file": "'//esc//'", "format": "'//trim(record%format)//'", "format_detected": '// &
               trim(merge('true ', 'false', record%detected))//', "units": "'//trim(record%units)// &
               '", "samples": '//trim(fmt_int(record%npts))//', "dt_s": '//trim(json_real(record%dt))// &
               ', "scale": '//trim(json_real(record%scale))//', "peak_acc_mps2": '// &
               trim(json_real(record%peak_acc))//', "sha256": "'//trim(record%sha256)//'"')
      if (allocated(record%title)) then
         call json_escape(record%title, esc)
         call put(jt, ', "title": "'//esc//'"')
      end if
      call put(jt, '},'//nl)
   end subroutine record_item

   !> The model's size, technique and laws, the stuck system's first mode and the steps (the
   !> technique's set-up).
   subroutine model_part(jt, model, res)
      type(json_text), intent(inout) :: jt     !! the summary
      type(model_type), intent(in) :: model    !! the model run
      type(result_type), intent(in) :: res     !! its result
      type(run_setup) :: setup
      integer :: d

      setup = setup_of(res)
      call kint(jt, 'n_dof', res%n_dof)
      call kint(jt, 'n_devices', res%n_devices)
      call kword(jt, 'technique', technique_name(res%technique))
      call ks(jt, 'device_law', [character(len=keyword_len) :: (law_name(model%dev(d)%law), d=1, model%n_devices)])
      call kreal(jt, res, 'period_stuck_s', setup%period_stuck)
      call kreal(jt, res, 'xi_stuck', setup%xi_stuck)
      call kreal(jt, res, 'dt1_s', setup%dt1)
      call kreal(jt, res, 'dt2_s', setup%dt2)
      call kreal(jt, res, 'dt_min_s', setup%dt_min)
   end subroutine model_part

   !> Whether dt1 resolves the highest modes (fd_mode_resolution): omega_max, omega_max dt1
   !> and the verdict.
   subroutine mode_part(jt, res, verdict)
      type(json_text), intent(inout) :: jt     !! the summary
      type(result_type), intent(in) :: res     !! the result
      character(len=*), intent(in) :: verdict  !! its check's outcome
      type(run_setup) :: setup

      setup = setup_of(res)
      call kreal(jt, res, 'omega_max_rad_s', res%omega_max)
      call kreal(jt, res, 'omega_max_dt1', res%omega_max*setup%dt1)
      call kword(jt, 'mode_resolution', verdict)
   end subroutine mode_part

   !> Whether dt1 resolves a harmonic table motion (fd_harmonic_resolution): the step's error
   !> per DOF and the verdict.
   subroutine harmonic_part(jt, step_error, verdict)
      type(json_text), intent(inout) :: jt     !! the summary
      real(dp), intent(in) :: step_error(:)    !! per DOF: the step's error in the steady state
      character(len=*), intent(in) :: verdict  !! its check's outcome

      call kr(jt, 'harmonic_step_error', step_error)
      call kword(jt, 'harmonic_resolution', verdict)
   end subroutine harmonic_part

   !> Whether dt1 resolves a recorded table motion (fd_record_resolution).
   subroutine record_step_part(jt, res, verdict)
      type(json_text), intent(inout) :: jt     !! the summary
      type(result_type), intent(in) :: res     !! the result
      character(len=*), intent(in) :: verdict  !! its check's outcome

      call kr(jt, 'record_step_error', res%record_error)
      call kr(jt, 'record_step_error_stuck', res%record_error_stuck)
      call kr(jt, 'record_step_error_free', res%record_error_free)
      call kword(jt, 'record_resolution', verdict)
      call kword(jt, 'record_step_system', record_system_names(res%record_system))
   end subroutine record_step_part

   !> Whether dt1 resolves the sticking springs' ringing (fd_stick_ringing): per device the
   !> frequency error, the ringing ratio, amplitude and margin, then the verdict.
   subroutine stick_part(jt, freq_error, ratio, ringing, margin, verdict)
      type(json_text), intent(inout) :: jt     !! the summary
      real(dp), intent(in) :: freq_error(:)    !! 1 - omega~/omega of each sticking spring's mode
      real(dp), intent(in) :: ratio(:)         !! largest ringing / margin of a dephased stick phase
      real(dp), intent(in) :: ringing(:)       !! that phase's ringing amplitude [N]
      real(dp), intent(in) :: margin(:)        !! that phase's margin [N]
      character(len=*), intent(in) :: verdict  !! its check's outcome

      call kr(jt, 'stick_frequency_error', freq_error)
      call kr(jt, 'stick_ringing_ratio', ratio)
      call kr(jt, 'stick_ringing_N', ringing)
      call kr(jt, 'stick_margin_N', margin)
      call kword(jt, 'stick_resolution', verdict)
   end subroutine stick_part

   !> Whether the step damps the velocity-law bands (fd_band_alternation): per device x, the
   !> alternation's amplitude and its time, then the verdict.
   subroutine band_part(jt, x, alternation, alternation_time, verdict)
      type(json_text), intent(inout) :: jt        !! the summary
      real(dp), intent(in) :: x(:)                !! (1 - gamma) dt1 (c_i / m_i + c_j / m_j)
      real(dp), intent(in) :: alternation(:)      !! largest step-to-step alternation of the band force [N]
      real(dp), intent(in) :: alternation_time(:) !! its time [s] (null where there is none)
      character(len=*), intent(in) :: verdict     !! its check's outcome

      call kr(jt, 'band_x', x)
      call kr(jt, 'band_alternation_N', alternation)
      call kr(jt, 'band_alternation_s', alternation_time, alternation /= 0.0_dp)
      call kword(jt, 'band_resolution', verdict)
   end subroutine band_part

   !> The peaks per DOF and device, with their times, the devices' phase changes, and each
   !> device's slip excursions, dissipated energy and slip travel.
   subroutine peaks_part(jt, res)
      type(json_text), intent(inout) :: jt     !! the summary
      type(result_type), intent(in) :: res     !! the result

      call kr(jt, 'peak_u_m', res%peak_u)
      call kr(jt, 'peak_u_time_s', res%peak_u_time, res%peak_u /= 0.0_dp)
      call kr(jt, 'peak_v_mps', res%peak_v)
      call kr(jt, 'peak_aabs_mps2', res%peak_aabs)
      call kr(jt, 'peak_aabs_time_s', res%peak_aabs_time, res%peak_aabs /= 0.0_dp)
      call kr(jt, 'peak_s_m', res%peak_s)
      call kr(jt, 'peak_force_N', res%peak_force)
      call ki(jt, 'stick_to_slip', res%stick_to_slip)
      call ki(jt, 'slip_to_stick', res%slip_to_stick)
      call ki(jt, 'slip_reversals', res%reversals)
      call ki(jt, 'slip_excursions', res%slip_excursions)
      call kr(jt, 'dissipated_energy_J', res%dissipated)
      call kr(jt, 'slip_travel_m', res%slip_travel)
   end subroutine peaks_part

   !> The planar bearings (&bearings): per bearing its label, the peak resultant displacement
   !> |(s_x, s_y)| with its direction (from x, counter-clockwise) and time, the residual
   !> resultant displacement at the run's end with its direction, and the energy its friction
   !> dissipated (its two components'), its travel and reversals; the isolation shear's peaks
   !> along x, y and of the resultant, with their times.
   subroutine bearings_part(jt, model, res)
      type(json_text), intent(inout) :: jt     !! the summary
      type(model_type), intent(in) :: model    !! the model
      type(result_type), intent(in) :: res     !! the result
      real(dp), parameter :: deg = 180.0_dp/acos(-1.0_dp)
      character(len=label_len) :: labels(res%n_bearings)
      character(len=*), parameter :: axis(3) = [character(len=2) :: '_x', '_y', '']
      real(dp) :: residual(res%n_bearings), angle(res%n_bearings), energy(res%n_bearings)
      integer :: b, d, k

      do b = 1, res%n_bearings
         d = res%bearing_dev(1, b)
         labels(b) = model%dev(d)%label
         labels(b)(max(1, len_trim(labels(b)) - 1):) = ''
         residual(b) = hypot(res%bearing_last(1, b), res%bearing_last(2, b))
         angle(b) = atan2(res%bearing_last(2, b), res%bearing_last(1, b))*deg
         energy(b) = res%dissipated(d) + res%dissipated(res%bearing_dev(2, b))
      end do
      call ks(jt, 'bearing_labels', labels)
      call kr(jt, 'bearing_peak_displacement_m', res%bearing_peak)
      call kr(jt, 'bearing_peak_direction_deg', res%bearing_peak_angle, res%bearing_peak > 0.0_dp)
      call kr(jt, 'bearing_peak_time_s', res%bearing_peak_time, res%bearing_peak > 0.0_dp)
      call kr(jt, 'bearing_residual_displacement_m', residual)
      call kr(jt, 'bearing_residual_direction_deg', angle, residual > 0.0_dp)
      call kr(jt, 'bearing_dissipated_energy_J', energy)
      call kr(jt, 'bearing_slip_travel_m', res%bearing_travel)
      call ki(jt, 'bearing_slip_reversals', res%bearing_reversals)
      do k = 1, 3
         call kv(jt, 'peak_isolation_shear'//trim(axis(k))//'_N', trim(json_real(res%peak_iso_shear(k))))
         call kv(jt, 'peak_isolation_shear'//trim(axis(k))//'_time_s', &
                 trim(merge(json_real(res%peak_iso_shear_time(k)), 'null'//repeat(' ', 28), res%peak_iso_shear(k) > 0.0_dp)))
      end do
      call kr(jt, 'bearing_min_normal_force_N', res%bearing_n_min)
      call kr(jt, 'bearing_max_normal_force_N', res%bearing_n_max)
      call ki(jt, 'bearing_uplift_count', res%bearing_uplifts)
      call kr(jt, 'bearing_uplift_duration_s', res%bearing_uplift_time)
      call kr(jt, 'bearing_uplift_first_time_s', res%bearing_uplift_first, res%bearing_uplifts > 0)
      if (allocated(res%bearing_uplift_peak)) call kr(jt, 'bearing_uplift_peak_m', res%bearing_uplift_peak)
   end subroutine bearings_part

   !> What the technique did: the part of the technique that ran (its own statistics, under
   !> the summary's counter keys; fd_statistics).
   subroutine statistics_part(jt, res)
      type(json_text), intent(inout) :: jt     !! the summary
      type(result_type), intent(in) :: res     !! the result

      if (res%newmark%ran) then
         call newmark_part(jt, res%newmark)
      else if (res%exact%ran) then
         call event_driven_part(jt, res%exact)
      else
         call moreau_jean_part(jt, res%moreau_jean)
      end if
   end subroutine statistics_part

   !> Newmark's steps of each size, refinements, factorizations and linear system.
   subroutine newmark_part(jt, st)
      type(json_text), intent(inout) :: jt        !! the summary
      type(newmark_stats), intent(in) :: st       !! Newmark's statistics

      call counts_part(jt, newmark_counts(st))
      call patterns_part(jt, newmark_counts(st))
   end subroutine newmark_part

   !> The exact technique's intervals, matrix exponentials and events; its peaks are the
   !> exact extrema; its event times and accumulation points.
   subroutine event_driven_part(jt, st)
      type(json_text), intent(inout) :: jt          !! the summary
      type(event_driven_stats), intent(in) :: st    !! the exact technique's statistics

      call counts_part(jt, event_driven_counts(st))
      call kv(jt, 'peaks_exact', 'true')
      call kr(jt, 'event_times_s', st%event_time(1:st%n_event_times))
      call kint(jt, 'accumulation_points', st%accumulations)
      call kr(jt, 'accumulation_times_s', st%accumulation_time(1:st%n_accumulation_times))
      call patterns_part(jt, event_driven_counts(st))
   end subroutine event_driven_part

   !> Moreau-Jean's steps, factorizations, patterns and Lemke fallbacks.
   subroutine moreau_jean_part(jt, st)
      type(json_text), intent(inout) :: jt         !! the summary
      type(moreau_jean_stats), intent(in) :: st    !! Moreau-Jean's statistics

      call counts_part(jt, moreau_jean_counts(st))
      call patterns_part(jt, moreau_jean_counts(st))
   end subroutine moreau_jean_part

   !> The summary's counter keys of every technique, from steps_dt1 to events: the counts of
   !> steps and factorizations (a table of keys), the linear system, its bandwidth, the events.
   subroutine counts_part(jt, c)
      type(json_text), intent(inout) :: jt     !! the summary
      type(summary_counts), intent(in) :: c    !! a technique's counters under these keys
      character(len=*), parameter :: keys(10) = [character(len=22) :: 'steps_dt1', 'steps_nested', &
                                                 'steps_implicit', 'implicit_redos', 'implicit_fallbacks', &
                                                 'steps_dt2', 'steps_finer', 'factorizations', 'factor_updates', &
                                                 'partial_factorizations']
      integer :: k

      associate (counts => [c%steps_dt1, c%steps_nested, c%steps_implicit, c%implicit_redos, c%implicit_fallbacks, &
                            c%steps_dt2, c%steps_finer, c%factorizations, c%factor_updates, c%partial_factorizations])
         do k = 1, size(keys)
            call kint(jt, trim(keys(k)), counts(k))
         end do
      end associate
      call kword(jt, 'linear_system', storage_name(c%storage))
      call kint(jt, 'half_bandwidth', c%bandwidth)
      call kint(jt, 'events', c%events)
   end subroutine counts_part

   !> The summary's last counter keys of every technique: patterns_solved, lcp_fallbacks.
   subroutine patterns_part(jt, c)
      type(json_text), intent(inout) :: jt     !! the summary
      type(summary_counts), intent(in) :: c    !! a technique's counters under these keys

      call kint(jt, 'patterns_solved', c%patterns)
      call kint(jt, 'lcp_fallbacks', c%lcp_fallbacks)
   end subroutine patterns_part

   !> The linear system's storage in words: 1 dense, 2 banded, else none.
   pure function storage_name(storage) result(name)
      integer, intent(in) :: storage   !! result_type's storage
      character(len=8) :: name         !! its name in the summary

      select case (storage)
      case (1)
         name = 'dense'
      case (2)
         name = 'banded'
      case (3)
         name = 'sparse'
      case default
         name = 'none'
      end select
   end function storage_name

   !> The correctness condition's violations (eqs. 9, 12): count, first times and devices.
   subroutine correctness_part(jt, res)
      type(json_text), intent(inout) :: jt     !! the summary
      type(result_type), intent(in) :: res     !! the result

      call kint(jt, 'correctness_violations', res%violations)
      call kr(jt, 'violation_times_s', res%violation_time(1:res%n_violation_times))
      call ki(jt, 'violation_devices', res%violation_device(1:res%n_violation_times))
   end subroutine correctness_part

   !> A speed-dependent mu: the fixed point's passes and the steps left unconverged.
   subroutine mu_part(jt, res)
      type(json_text), intent(inout) :: jt     !! the summary
      type(result_type), intent(in) :: res     !! the result

      call kint(jt, 'mu_passes', res%newmark%mu_passes)
      call kint(jt, 'mu_unconverged_steps', res%mu_unconverged)
      call kreal(jt, res, 'mu_unconverged_s', res%mu_unconverged_time)
      call kreal(jt, res, 'mu_unconverged_misfit', res%mu_misfit)
   end subroutine mu_part

   !> The energy balance and its verdict.
   subroutine energy_part(jt, res, verdict)
      type(json_text), intent(inout) :: jt     !! the summary
      type(result_type), intent(in) :: res     !! the result
      character(len=*), intent(in) :: verdict  !! its check's outcome

      call kreal(jt, res, 'energy_input_J', res%e_input)
      call kreal(jt, res, 'energy_kinetic_J', res%e_kinetic)
      call kreal(jt, res, 'energy_strain_J', res%e_strain)
      call kreal(jt, res, 'energy_viscous_J', res%e_viscous)
      call kreal(jt, res, 'energy_friction_J', res%e_friction)
      call kreal(jt, res, 'energy_device_elastic_J', res%e_device)
      call kreal(jt, res, 'energy_residual_J', res%e_residual)
      call kreal(jt, res, 'energy_residual_ratio', res%e_residual_ratio)
      call kword(jt, 'energy_balance', verdict)
   end subroutine energy_part

   !> Whether the first period and a record's peak acceleration lie where structures and
   !> earthquakes have theirs (fd_warnings' period and record checks): their verdicts.
   subroutine plausibility_part(jt, checks)
      type(json_text), intent(inout) :: jt     !! the summary
      type(check_type), intent(in) :: checks(:) !! the run's checks

      call kword(jt, 'period_plausibility', outcome_of(checks, 'period_plausibility'))
      call kword(jt, 'record_plausibility', outcome_of(checks, 'record_plausibility'))
   end subroutine plausibility_part

   !> What produced the run, the table motion, the labels, the damping, the modes, the
   !> residual deformations and the storeys (fd_engineering).
   subroutine engineering_part(jt, model, res)
      type(json_text), intent(inout) :: jt     !! the summary
      type(model_type), intent(in) :: model    !! the model run
      type(result_type), intent(in) :: res     !! the result

      call kword(jt, 'deck_sha256', model%deck_sha256)
      associate (eng => res%eng)
         if (eng%excitation >= 1 .and. eng%excitation <= size(excitation_types)) then
            call kword(jt, 'excitation_type', excitation_types(eng%excitation)%name)
         else
            call kv(jt, 'excitation_type', '"unknown"')
         end if
         call kreal(jt, res, 'excitation_frequency_Hz', eng%frequency)
         call kreal(jt, res, 'duration_s', eng%duration)
         call ks(jt, 'dof_labels', eng%dof_label)
         call ks(jt, 'device_labels', eng%device_label)
         call kreal(jt, res, 'damping_a0_per_s', eng%a0)
         call kreal(jt, res, 'damping_a1_s', eng%a1)
         call modes_part(jt, 'stuck', eng%stuck)
         call modes_part(jt, 'free', eng%free)
         call kr(jt, 'residual_s_m', eng%residual_s)
         call kreal(jt, res, 'peak_base_shear_N', eng%peak_shear(0))
         call kreal(jt, res, 'peak_base_shear_time_s', eng%peak_shear_time(0))
         call kreal(jt, res, 'residual_base_shear_N', eng%shear(0))
      end associate
      call storeys_part(jt, res%eng)
      if (res%eng%n_floors > 0) call floors_part(jt, res)
   end subroutine engineering_part

   !> A building of rigid floors: the base shears along x and y and the base torque about
   !> the plan origin, the modal mass ratios along x, y and rz, the floors' rotations and
   !> the absolute accelerations at their corners, the plan and the braces in it.
   subroutine floors_part(jt, res)
      type(json_text), intent(inout) :: jt     !! the summary
      type(result_type), intent(in) :: res     !! the result
      character(len=*), parameter :: base(3) = [character(len=13) :: 'base_shear_x', 'base_shear_y', &
                                                'base_torque']
      character(len=*), parameter :: unit(3) = [character(len=2) :: 'N', 'N', 'Nm']
      character(len=*), parameter :: axis(3) = [character(len=2) :: 'x', 'y', 'rz']
      real(dp), allocatable :: x(:), tx(:)
      integer :: a, f

      associate (eng => res%eng)
         do a = 1, 3
            call kr1(trim(base(a))//'_'//trim(unit(a)), eng%peak_base3(a), .true.)
            call kr1(trim(base(a))//'_time_s', eng%peak_base3_time(a), eng%peak_base3(a) /= 0.0_dp)
            call kv(jt, 'residual_'//trim(base(a))//'_'//trim(unit(a)), trim(json_real(eng%base3(a))))
         end do
         do a = 1, 3
            x = eng%ratio_stuck(:, a)
            call kr(jt, 'modal_mass_ratio_stuck_'//trim(axis(a)), x)
         end do
         do a = 1, 3
            x = eng%ratio_free(:, a)
            call kr(jt, 'modal_mass_ratio_free_'//trim(axis(a)), x)
         end do
         x = [(res%peak_u(3*f), f=1, eng%n_floors)]
         tx = [(res%peak_u_time(3*f), f=1, eng%n_floors)]
         call kr(jt, 'peak_floor_rotation_rad', x)
         call kr(jt, 'peak_floor_rotation_time_s', tx, x /= 0.0_dp)
         call kr(jt, 'peak_corner_aabs_mps2', reshape(eng%peak_corner_aabs, [2*eng%n_floors]), &
                 reshape(eng%half_plan, [2*eng%n_floors]) > 0.0_dp)
         call kr(jt, 'peak_corner_aabs_time_s', reshape(eng%peak_corner_aabs_time, [2*eng%n_floors]), &
                 reshape(eng%peak_corner_aabs, [2*eng%n_floors]) /= 0.0_dp)
         call kr(jt, 'floor_cm_x_m', eng%floor_x)
         call kr(jt, 'floor_cm_y_m', eng%floor_y)
         call kr(jt, 'floor_plan_x_m', eng%floor_lx, eng%floor_lx > 0.0_dp)
         call kr(jt, 'floor_plan_y_m', eng%floor_ly, eng%floor_ly > 0.0_dp)
         call ki(jt, 'device_storey', eng%dev_storey)
         call kr(jt, 'device_plan_x_m', eng%dev_x, eng%dev_storey > 0)
         call kr(jt, 'device_plan_y_m', eng%dev_y, eng%dev_storey > 0)
         call kr(jt, 'device_angle_deg', eng%dev_angle, eng%dev_storey > 0)
      end associate
   contains
      !> 'peak_<key>' as a number, or null when not defined.
      subroutine kr1(key, x, defined)
         character(len=*), intent(in) :: key
         real(dp), intent(in) :: x
         logical, intent(in) :: defined
         call kv(jt, 'peak_'//key, trim(merge(json_real(x), 'null' // repeat(' ', 28), defined)))
      end subroutine kr1
   end subroutine floors_part

   !> The storeys: labels, nodes, heights, drifts (and their ratios) and shears.
   subroutine storeys_part(jt, eng)
      type(json_text), intent(inout) :: jt        !! the summary
      type(engineering_type), intent(in) :: eng   !! the engineering outputs
      real(dp), allocatable :: ratio(:)
      integer :: i

      call kint(jt, 'n_storeys', eng%n_storeys)
      call ks(jt, 'storey_labels', eng%storey_label)
      call put(jt, '  "storey_nodes": [')
      do i = 1, eng%n_storeys
         call put(jt, '['//trim(fmt_int(eng%storey_i(i)))//', '//trim(fmt_int(eng%storey_j(i)))//']')
         if (i < eng%n_storeys) call put(jt, ', ')
      end do
      call put(jt, '],'//nl)
      call kr(jt, 'storey_height_m', eng%height)
      call kr(jt, 'peak_drift_m', eng%peak_drift)
      call kr(jt, 'peak_drift_time_s', eng%peak_drift_time, eng%peak_drift /= 0.0_dp)
      call kr(jt, 'residual_drift_m', eng%drift)
      ! a ratio without a storey height is undefined (null), not 0
      allocate (ratio(eng%n_storeys))
      ratio = 0.0_dp
      where (eng%height > 0.0_dp) ratio = eng%peak_drift/eng%height
      call kr(jt, 'peak_drift_ratio', ratio, eng%height > 0.0_dp)
      where (eng%height > 0.0_dp) ratio = eng%drift/eng%height
      call kr(jt, 'residual_drift_ratio', ratio, eng%height > 0.0_dp)
      call kr(jt, 'peak_storey_shear_N', eng%peak_shear(1:))
      call kr(jt, 'peak_storey_shear_time_s', eng%peak_shear_time(1:), eng%peak_shear(1:) /= 0.0_dp)
      call kr(jt, 'residual_storey_shear_N', eng%shear(1:))
      ! a building of rigid floors: the drift at the floors' plan corners (undefined, null,
      ! for a floor given by its inertia, whose plan is not known)
      if (.not. allocated(eng%peak_corner)) return
      call kr(jt, 'peak_corner_drift_m', eng%peak_corner, eng%has_corners)
      where (eng%height > 0.0_dp) ratio = eng%peak_corner/eng%height
      call kr(jt, 'peak_corner_drift_ratio', ratio, eng%has_corners .and. eng%height > 0.0_dp)
   end subroutine storeys_part

   !> The modes of one system: status, periods (0: a rigid-body mode), shapes, mass ratios, damping.
   subroutine modes_part(jt, name, m)
      type(json_text), intent(inout) :: jt     !! the summary
      character(len=*), intent(in) :: name     !! 'stuck' or 'free'
      type(modes_type), intent(in) :: m        !! its modes
      integer :: j

      select case (m%status)
      case (modes_flexible)
         call kv(jt, 'modes_'//name//'_status', '"flexible"')
      case (modes_rigid)
         call kv(jt, 'modes_'//name//'_status', '"rigid"')
      case (modes_unrestrained)
         call kv(jt, 'modes_'//name//'_status', '"unrestrained"')
      case default
         call kv(jt, 'modes_'//name//'_status', '"not computed"')
         call kr(jt, 'periods_'//name//'_s', [real(dp) ::])
         call put(jt, '  "mode_shapes_'//name//'": [],'//nl)
         call kr(jt, 'modal_mass_ratio_'//name, [real(dp) ::])
         call kr(jt, 'modal_xi_'//name, [real(dp) ::])
         return
      end select
      ! a rigid-body mode (w = 0): period (infinite) and damping ratio undefined (null)
      call kr(jt, 'periods_'//name//'_s', merge(m%period, 0.0_dp, m%omega2 > 0.0_dp), m%omega2 > 0.0_dp)
      call put(jt, '  "mode_shapes_'//name//'": [')
      do j = 1, m%n
         call put_reals(jt, m%shape(:, j))
         if (j < m%n) call put(jt, ', ')
      end do
      call put(jt, '],'//nl)
      call kr(jt, 'modal_mass_ratio_'//name, m%mass_ratio)
      call kr(jt, 'modal_xi_'//name, merge(m%xi, 0.0_dp, m%omega2 > 0.0_dp), m%omega2 > 0.0_dp)
   end subroutine modes_part

   !> The run's warnings (fd_warnings: the lines of the checks that warn), one string each.
   subroutine warnings_part(jt, checks)
      type(json_text), intent(inout) :: jt     !! the summary
      type(check_type), intent(in) :: checks(:) !! the run's checks
      type(warning_text), allocatable :: w(:)
      character(len=:), allocatable :: e
      integer :: k

      call check_warnings(checks, w)
      call put(jt, '  "warnings": [')
      do k = 1, size(w)
         call json_escape(w(k)%text, e)
         call put(jt, nl//'    "'//e//'"')
         if (k < size(w)) call put(jt, ',')
      end do
      call put(jt, '],'//nl)
   end subroutine warnings_part

   !> Append to the text (capacity doubled when full: linear in the length, not quadratic).
   subroutine put(jt, text)
      type(json_text), intent(inout) :: jt     !! the text
      character(len=*), intent(in) :: text     !! what to append
      character(len=:), allocatable :: bigger

      if (jt%pos + len(text) > len(jt%buf)) then
         allocate (character(len=2*(jt%pos + len(text))) :: bigger)
         bigger(1:jt%pos) = jt%buf(1:jt%pos)
         call move_alloc(bigger, jt%buf)
      end if
      jt%buf(jt%pos + 1:jt%pos + len(text)) = text
      jt%pos = jt%pos + len(text)
   end subroutine put

   !> A key and its JSON value, as a line of the object.
   subroutine kv(jt, key, val)
      type(json_text), intent(inout) :: jt     !! the text
      character(len=*), intent(in) :: key, val !! the key and its value's text

      call put(jt, '  "'//key//'": '//val//','//nl)
   end subroutine kv

   !> A key and a word: its text trimmed, in quotes (a name or a verdict, which needs no
   !> escape).
   subroutine kword(jt, key, word)
      type(json_text), intent(inout) :: jt     !! the text
      character(len=*), intent(in) :: key, word !! the key and its word

      call kv(jt, key, '"'//trim(word)//'"')
   end subroutine kword

   !> A list of strings.
   subroutine ks(jt, key, x)
      type(json_text), intent(inout) :: jt     !! the text
      character(len=*), intent(in) :: key     !! the key
      character(len=*), intent(in) :: x(:)    !! the strings (trimmed)
      character(len=:), allocatable :: e
      integer :: k

      call put(jt, '  "'//key//'": [')
      do k = 1, size(x)
         call json_escape(trim(x(k)), e)
         call put(jt, '"'//e//'"')
         if (k < size(x)) call put(jt, ', ')
      end do
      call put(jt, '],'//nl)
   end subroutine ks

   !> An integer.
   subroutine kint(jt, key, n)
      type(json_text), intent(inout) :: jt     !! the text
      character(len=*), intent(in) :: key     !! the key
      integer, intent(in) :: n                !! the value

      call kv(jt, key, trim(fmt_int(n)))
   end subroutine kint

   !> A real number: null when the key is undefined for this result (fd_undefined).
   subroutine kreal(jt, res, key, x)
      type(json_text), intent(inout) :: jt     !! the text
      type(result_type), intent(in) :: res     !! the result (whether the key is defined)
      character(len=*), intent(in) :: key     !! the key
      real(dp), intent(in) :: x               !! the value

      if (len_trim(undefined_why(res, key)) > 0) then
         call kv(jt, key, 'null')
      else
         call kv(jt, key, trim(json_real(x)))
      end if
   end subroutine kreal

   !> A list of reals; with `defined`, null for each item not defined.
   subroutine kr(jt, key, x, defined)
      type(json_text), intent(inout) :: jt     !! the text
      character(len=*), intent(in) :: key     !! the key
      real(dp), intent(in) :: x(:)            !! the values
      logical, intent(in), optional :: defined(:) !! which are defined

      call put(jt, '  "'//key//'": ')
      call put_reals(jt, x, defined)
      call put(jt, ','//nl)
   end subroutine kr

   !> '[x1, x2, ...]' appended number by number (put: linear in the length).
   subroutine put_reals(jt, x, defined)
      type(json_text), intent(inout) :: jt     !! the text
      real(dp), intent(in) :: x(:)            !! the values
      logical, intent(in), optional :: defined(:) !! which are defined
      logical :: def
      integer :: k

      call put(jt, '[')
      do k = 1, size(x)
         def = .true.
         if (present(defined)) def = defined(k)
         if (def) then
            call put(jt, trim(json_real(x(k))))
         else
            call put(jt, 'null')
         end if
         if (k < size(x)) call put(jt, ', ')
      end do
      call put(jt, ']')
   end subroutine put_reals

   !> A list of integers.
   subroutine ki(jt, key, x)
      type(json_text), intent(inout) :: jt     !! the text
      character(len=*), intent(in) :: key     !! the key
      integer, intent(in) :: x(:)             !! the values
      integer :: k

      call put(jt, '  "'//key//'": [')
      do k = 1, size(x)
         call put(jt, trim(fmt_int(x(k))))
         if (k < size(x)) call put(jt, ', ')
      end do
      call put(jt, '],'//nl)
   end subroutine ki

   !> A real as JSON: 17 significant digits (null when not finite), left-adjusted.
   pure function json_real(x) result(str)
      use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
      real(dp), intent(in) :: x
      character(len=32) :: str
      character(len=stream_value_width) :: row
      real(dp) :: one(1)
      if (.not. ieee_is_finite(x)) then
         str = 'null'
         return
      end if
      ! the stream's formatter: the digits of write (str, '(es24.16e3)') x, byte for byte,
      ! without libgfortran's format parsing (a summary has a few values per DOF and device)
      one(1) = x
      call format_row(one, row)
      str = adjustl(row(1:stream_value_width - 1))
   end function json_real

   !> A text as the content of a JSON string: '"' and '\' escaped, control characters as
   !> \u00XX, well-formed UTF-8 sequences kept, and any other byte (Latin-1 text, a stray
   !> byte of a path) written as the character of its Latin-1 reading (\u00XX): the summary is
   !> valid UTF-8 JSON whatever the bytes of a path, a label or a record title.
   pure subroutine json_escape(s, r)
      character(len=*), intent(in) :: s                 !! bytes
      character(len=:), allocatable, intent(out) :: r   !! the escaped text
      character(len=16), parameter :: hex = '0123456789abcdef'
      character(len=:), allocatable :: buf
      integer :: i, pos, c, n, k, lo, hi

      allocate (character(len=6*len(s)) :: buf)
      pos = 0
      i = 1
      do while (i <= len(s))
         c = iachar(s(i:i))
         if (s(i:i) == '"' .or. s(i:i) == '\') then
            buf(pos + 1:pos + 2) = '\'//s(i:i)
            pos = pos + 2
            i = i + 1
            cycle
         else if (c >= 32 .and. c < 128) then
            buf(pos + 1:pos + 1) = s(i:i)
            pos = pos + 1
            i = i + 1
            cycle
         end if
         ! the continuation bytes a well-formed UTF-8 sequence led by c has (0: none), and the
         ! range of its second byte (no overlong form, no surrogate, nothing above U+10FFFF)
         n = 0
         lo = 128
         hi = 191
         select case (c)
         case (194:223)
            n = 1
         case (224)
            n = 2
            lo = 160
         case (225:236, 238:239)
            n = 2
         case (237)
            n = 2
            hi = 159
         case (240)
            n = 3
            lo = 144
         case (241:243)
            n = 3
         case (244)
            n = 3
            hi = 143
         end select
         if (n > 0 .and. i + n <= len(s)) then
            if (iachar(s(i + 1:i + 1)) >= lo .and. iachar(s(i + 1:i + 1)) <= hi) then
               do k = 2, n
                  if (iachar(s(i + k:i + k)) < 128 .or. iachar(s(i + k:i + k)) > 191) exit
               end do
               if (k > n) then
                  buf(pos + 1:pos + n + 1) = s(i:i + n)
                  pos = pos + n + 1
                  i = i + n + 1
                  cycle
               end if
            end if
         end if
         ! a control character, or a byte that starts no well-formed sequence: \u00XX
         buf(pos + 1:pos + 6) = '\u00'//hex(c/16 + 1:c/16 + 1)//hex(mod(c, 16) + 1:mod(c, 16) + 1)
         pos = pos + 6
         i = i + 1
      end do
      r = buf(1:pos)
   end subroutine json_escape

end module fd_output
