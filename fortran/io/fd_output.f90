!> Output files of a run: the time-history CSV (a header naming every column with its
!> unit, 17 significant digits) and the summary (JSON). Each is written to a temporary
!> name unique to the writer and the pair is committed under a lock (write_outputs); on
!> any error no output file is left behind and earlier outputs of the name stay.
module fd_output
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_long, c_long_long, c_null_char
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real
   use fd_model, only: model_type, output_type, law_name, technique_name
   use fd_result, only: result_type, resolution_names, energy_balance_names, record_system_names
   use fd_record, only: record_info
   use fd_warnings, only: warning_text, run_warnings
   use fd_undefined, only: undefined_why
   use fd_version, only: frictiondyn_version
   use fd_history_stream, only: format_row, stream_value_width
   use fd_names, only: excitation_types, keyword_len
   use fd_matrices, only: modes_type, modes_flexible, modes_rigid, modes_unrestrained
   use fd_fileops, only: c_lock_acquire, c_lock_release, c_unlink, c_rename, os_error, &
                         c_file_create, c_file_write, c_file_close, c_mkdir, lock_not_file
   use fd_tempfiles, only: temp_tag, remove_stale_temps
   implicit none
   private

   public :: output_type, write_outputs, write_output_files, output_paths, temp_output_paths, summary_json, &
             history_header, make_dir, remove_made_dirs

   interface
      function c_rmdir(path) bind(c, name='rmdir') result(stat)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int) :: stat
      end function c_rmdir
   end interface

   integer(c_int), parameter :: enoent = 2, eexist = 17

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
      character(len=1), parameter :: nl = achar(10)

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

   !> The summary of a run as a JSON object (keys documented in docs/namelist.md).
   subroutine summary_json(model, res, deck_path, js, record)
      type(model_type), intent(in) :: model                !! the model run
      type(result_type), intent(in) :: res                 !! its result
      character(len=*), intent(in) :: deck_path            !! deck named in the summary
      character(len=:), allocatable, intent(out) :: js     !! the JSON text
      type(record_info), intent(in), optional :: record    !! the record read, if any
      character(len=1), parameter :: nl = achar(10)
      character(len=:), allocatable :: esc, buf
      integer :: pos
      integer :: d

      call json_escape(deck_path, esc)
      pos = 0
      allocate (character(len=4096 + 64*(res%n_dof + res%n_devices)*8) :: buf)
      call put('{'//nl)
      call put('  "deck": "'//esc//'",'//nl)
      call put('  "frictiondyn_version": "'//frictiondyn_version//'",'//nl)
      if (present(record)) then
         if (allocated(record%path)) then
            call put('  "record": {')
            call json_escape(record%path, esc)
            call put('"file": "'//esc//'", "format": "'//trim(record%format)//'", "format_detected": '// &
                 trim(merge('true ', 'false', record%detected))//', "units": "'//trim(record%units)// &
                 '", "samples": '//trim(fmt_int(record%npts))//', "dt_s": '//trim(json_real(record%dt))// &
                 ', "scale": '//trim(json_real(record%scale))//', "peak_acc_mps2": '// &
                 trim(json_real(record%peak_acc))//', "sha256": "'//trim(record%sha256)//'"')
            if (allocated(record%title)) then
               call json_escape(record%title, esc)
               call put(', "title": "'//esc//'"')
            end if
            call put('},'//nl)
         end if
      end if
      call kint('n_dof', res%n_dof)
      call kint('n_devices', res%n_devices)
      call kv('technique', '"'//trim(technique_name(res%technique))//'"')
      call ks('device_law', [character(len=keyword_len) :: (law_name(model%dev(d)%law), d=1, model%n_devices)])
      call kreal('period_stuck_s', res%period_stuck)
      call kreal('xi_stuck', res%xi_stuck)
      call kreal('dt1_s', res%dt1)
      call kreal('dt2_s', res%dt2)
      call kreal('dt_min_s', res%dt_min)
      call kreal('omega_max_rad_s', res%omega_max)
      call kreal('omega_max_dt1', res%omega_max*res%dt1)
      call kv('mode_resolution', '"'//trim(resolution_names(res%mode_resolution))//'"')
      call kr('harmonic_step_error', res%harmonic_error)
      call kv('harmonic_resolution', '"'//trim(resolution_names(res%harmonic_resolution))//'"')
      call kr('record_step_error', res%record_error)
      call kr('record_step_error_stuck', res%record_error_stuck)
      call kr('record_step_error_free', res%record_error_free)
      call kv('record_resolution', '"'//trim(resolution_names(res%record_resolution))//'"')
      call kv('record_step_system', '"'//trim(record_system_names(res%record_system))//'"')
      call kr('stick_frequency_error', res%stick_freq_error)
      call kr('stick_ringing_ratio', res%stick_ringing_ratio)
      call kr('stick_ringing_N', res%stick_ringing)
      call kr('stick_margin_N', res%stick_margin)
      call kv('stick_resolution', '"'//trim(resolution_names(res%stick_resolution))//'"')
      call kr('band_x', res%band_x)
      call kr('band_alternation_N', res%band_alternation)
      call kr('band_alternation_s', res%band_alternation_time, res%band_alternation /= 0.0_dp)
      call kv('band_resolution', '"'//trim(resolution_names(res%band_resolution))//'"')
      call kr('peak_u_m', res%peak_u)
      call kr('peak_u_time_s', res%peak_u_time, res%peak_u /= 0.0_dp)
      call kr('peak_v_mps', res%peak_v)
      call kr('peak_aabs_mps2', res%peak_aabs)
      call kr('peak_aabs_time_s', res%peak_aabs_time, res%peak_aabs /= 0.0_dp)
      call kr('peak_s_m', res%peak_s)
      call kr('peak_force_N', res%peak_force)
      call ki('stick_to_slip', res%stick_to_slip)
      call ki('slip_to_stick', res%slip_to_stick)
      call ki('slip_reversals', res%reversals)
      call kint('steps_dt1', res%steps_dt1)
      call kint('steps_nested', res%steps_nested)
      call kint('steps_implicit', res%steps_implicit)
      call kint('implicit_redos', res%implicit_redos)
      call kint('implicit_fallbacks', res%implicit_fallbacks)
      call kint('steps_dt2', res%steps_dt2)
      call kint('steps_finer', res%steps_finer)
      call kint('factorizations', res%factorizations)
      call kint('factor_updates', res%factor_updates)
      call kint('partial_factorizations', res%partial_factorizations)
      select case (res%storage)
      case (1)
         call kv('linear_system', '"dense"')
      case (2)
         call kv('linear_system', '"banded"')
      case default
         call kv('linear_system', '"none"')
      end select
      call kint('half_bandwidth', res%bandwidth)
      call kint('events', res%events)
      if (res%exact_peaks) then
         ! the exact technique: peaks are the exact extrema; its event times, accumulations
         call kv('peaks_exact', 'true')
         call kr('event_times_s', res%event_time(1:res%n_event_times))
         call kint('accumulation_points', res%accumulations)
         call kr('accumulation_times_s', res%accumulation_time(1:res%n_accumulation_times))
      end if
      call kint('patterns_solved', res%patterns)
      call kint('lcp_fallbacks', res%lcp_fallbacks)
      call kint('correctness_violations', res%violations)
      call kr('violation_times_s', res%violation_time(1:res%n_violation_times))
      call ki('violation_devices', res%violation_device(1:res%n_violation_times))
      call kint('mu_passes', res%mu_passes)
      call kint('mu_unconverged_steps', res%mu_unconverged)
      call kreal('mu_unconverged_s', res%mu_unconverged_time)
      call kreal('mu_unconverged_misfit', res%mu_misfit)
      call kreal('energy_input_J', res%e_input)
      call kreal('energy_kinetic_J', res%e_kinetic)
      call kreal('energy_strain_J', res%e_strain)
      call kreal('energy_viscous_J', res%e_viscous)
      call kreal('energy_friction_J', res%e_friction)
      call kreal('energy_device_elastic_J', res%e_device)
      call kreal('energy_residual_J', res%e_residual)
      call kreal('energy_residual_ratio', res%e_residual_ratio)
      call kv('energy_balance', '"'//trim(energy_balance_names(res%energy_balance))//'"')
      call engineering_keys()
      call kint('samples', res%nout)
      call warnings_key()
      call put('  "run_time_s": '//trim(json_real(res%run_time))//nl//'}')
      js = buf(1:pos)
   contains
      !> Append to the text (capacity doubled when full: linear in the length, not quadratic).
      subroutine put(text)
         character(len=*), intent(in) :: text
         character(len=:), allocatable :: bigger
         if (pos + len(text) > len(buf)) then
            allocate (character(len=2*(pos + len(text))) :: bigger)
            bigger(1:pos) = buf(1:pos)
            call move_alloc(bigger, buf)
         end if
         buf(pos + 1:pos + len(text)) = text
         pos = pos + len(text)
      end subroutine put
      !> What produced the run, the names, the modes, the storeys (fd_engineering).
      subroutine engineering_keys()
         integer :: i
         real(dp), allocatable :: ratio(:)
         call kv('deck_sha256', '"'//trim(model%deck_sha256)//'"')
         associate (eng => res%eng)
            if (eng%excitation >= 1 .and. eng%excitation <= size(excitation_types)) then
               call kv('excitation_type', '"'//trim(excitation_types(eng%excitation)%name)//'"')
            else
               call kv('excitation_type', '"unknown"')
            end if
            call kreal('excitation_frequency_Hz', eng%frequency)
            call kreal('duration_s', eng%duration)
            call ks('dof_labels', eng%dof_label)
            call ks('device_labels', eng%device_label)
            call kreal('damping_a0_per_s', eng%a0)
            call kreal('damping_a1_s', eng%a1)
            call modes_keys('stuck', eng%stuck)
            call modes_keys('free', eng%free)
            call kr('residual_s_m', eng%residual_s)
            call kreal('peak_base_shear_N', eng%peak_shear(0))
            call kreal('peak_base_shear_time_s', eng%peak_shear_time(0))
            call kreal('residual_base_shear_N', eng%shear(0))
            call kint('n_storeys', eng%n_storeys)
            call ks('storey_labels', eng%storey_label)
            call put('  "storey_nodes": [')
            do i = 1, eng%n_storeys
               call put('['//trim(fmt_int(eng%storey_i(i)))//', '//trim(fmt_int(eng%storey_j(i)))//']')
               if (i < eng%n_storeys) call put(', ')
            end do
            call put('],'//nl)
            call kr('storey_height_m', eng%height)
            call kr('peak_drift_m', eng%peak_drift)
            call kr('peak_drift_time_s', eng%peak_drift_time, eng%peak_drift /= 0.0_dp)
            call kr('residual_drift_m', eng%drift)
            ! a ratio without a storey height is undefined (null), not 0
            allocate (ratio(eng%n_storeys))
            ratio = 0.0_dp
            where (eng%height > 0.0_dp) ratio = eng%peak_drift/eng%height
            call kr('peak_drift_ratio', ratio, eng%height > 0.0_dp)
            where (eng%height > 0.0_dp) ratio = eng%drift/eng%height
            call kr('residual_drift_ratio', ratio, eng%height > 0.0_dp)
            call kr('peak_storey_shear_N', eng%peak_shear(1:))
            call kr('peak_storey_shear_time_s', eng%peak_shear_time(1:), eng%peak_shear(1:) /= 0.0_dp)
            call kr('residual_storey_shear_N', eng%shear(1:))
         end associate
      end subroutine engineering_keys
      !> The modes of one system: status, periods (0: a rigid-body mode), shapes, mass ratios, damping.
      subroutine modes_keys(name, m)
         character(len=*), intent(in) :: name
         type(modes_type), intent(in) :: m
         integer :: j
         select case (m%status)
         case (modes_flexible)
            call kv('modes_'//name//'_status', '"flexible"')
         case (modes_rigid)
            call kv('modes_'//name//'_status', '"rigid"')
         case (modes_unrestrained)
            call kv('modes_'//name//'_status', '"unrestrained"')
         case default
            call kv('modes_'//name//'_status', '"not computed"')
            call kr('periods_'//name//'_s', [real(dp) ::])
            call put('  "mode_shapes_'//name//'": [],'//nl)
            call kr('modal_mass_ratio_'//name, [real(dp) ::])
            call kr('modal_xi_'//name, [real(dp) ::])
            return
         end select
         ! a rigid-body mode (w = 0): period (infinite) and damping ratio undefined (null)
         call kr('periods_'//name//'_s', merge(m%period, 0.0_dp, m%omega2 > 0.0_dp), m%omega2 > 0.0_dp)
         call put('  "mode_shapes_'//name//'": [')
         do j = 1, m%n
            call put_reals(m%shape(:, j))
            if (j < m%n) call put(', ')
         end do
         call put('],'//nl)
         call kr('modal_mass_ratio_'//name, m%mass_ratio)
         call kr('modal_xi_'//name, merge(m%xi, 0.0_dp, m%omega2 > 0.0_dp), m%omega2 > 0.0_dp)
      end subroutine modes_keys
      !> The run's warnings (fd_warnings), one string each.
      subroutine warnings_key()
         type(warning_text), allocatable :: w(:)
         character(len=:), allocatable :: e
         integer :: k
         call run_warnings(res, w)
         call put('  "warnings": [')
         do k = 1, size(w)
            call json_escape(w(k)%text, e)
            call put(nl//'    "'//e//'"')
            if (k < size(w)) call put(',')
         end do
         call put('],'//nl)
      end subroutine warnings_key
      !> Strings.
      subroutine ks(key, x)
         character(len=*), intent(in) :: key
         character(len=*), intent(in) :: x(:)
         integer :: k
         character(len=:), allocatable :: e
         call put('  "'//key//'": [')
         do k = 1, size(x)
            call json_escape(trim(x(k)), e)
            call put('"'//e//'"')
            if (k < size(x)) call put(', ')
         end do
         call put('],'//nl)
      end subroutine ks
      subroutine kv(key, val)
         character(len=*), intent(in) :: key, val
         call put('  "'//key//'": '//val//','//nl)
      end subroutine kv
      !> An integer.
      subroutine kint(key, n)
         character(len=*), intent(in) :: key
         integer, intent(in) :: n
         call kv(key, trim(fmt_int(n)))
      end subroutine kint
      !> A real number: null when the key is undefined for this result (fd_undefined).
      subroutine kreal(key, x)
         character(len=*), intent(in) :: key
         real(dp), intent(in) :: x
         if (len_trim(undefined_why(res, key)) > 0) then
            call kv(key, 'null')
         else
            call kv(key, trim(json_real(x)))
         end if
      end subroutine kreal
      !> A list of reals; with `defined`, null for each item not defined.
      subroutine kr(key, x, defined)
         character(len=*), intent(in) :: key
         real(dp), intent(in) :: x(:)
         logical, intent(in), optional :: defined(:)
         call put('  "'//key//'": ')
         call put_reals(x, defined)
         call put(','//nl)
      end subroutine kr
      !> '[x1, x2, ...]' appended number by number (put: linear in the length).
      subroutine put_reals(x, defined)
         real(dp), intent(in) :: x(:)
         logical, intent(in), optional :: defined(:)
         integer :: k
         logical :: def
         call put('[')
         do k = 1, size(x)
            def = .true.
            if (present(defined)) def = defined(k)
            if (def) then
               call put(trim(json_real(x(k))))
            else
               call put('null')
            end if
            if (k < size(x)) call put(', ')
         end do
         call put(']')
      end subroutine put_reals
      subroutine ki(key, x)
         character(len=*), intent(in) :: key
         integer, intent(in) :: x(:)
         integer :: k
         call put('  "'//key//'": [')
         do k = 1, size(x)
            call put(trim(fmt_int(x(k))))
            if (k < size(x)) call put(', ')
         end do
         call put('],'//nl)
      end subroutine ki
   end subroutine summary_json

   !> The header line of the history: name[unit] of each column, comma separated.
   pure subroutine history_header(res, line)
      type(result_type), intent(in) :: res                 !! the result
      character(len=:), allocatable, intent(out) :: line   !! the header
      integer :: j, pos, n

      n = 0
      do j = 1, res%ncol
         n = n + len_trim(res%names(j)) + len_trim(res%units(j)) + 3
      end do
      allocate (character(len=max(n - 1, 0)) :: line)
      pos = 0
      do j = 1, res%ncol
         n = len_trim(res%names(j)) + len_trim(res%units(j)) + 2
         line(pos + 1:pos + n) = trim(res%names(j))//'['//trim(res%units(j))//']'
         pos = pos + n
         if (j < res%ncol) then
            line(pos + 1:pos + 1) = ','
            pos = pos + 1
         end if
      end do
   end subroutine history_header

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
