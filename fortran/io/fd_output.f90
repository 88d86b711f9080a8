!> Output files of a run: the time-history CSV (a header naming every column with its
!> unit, 17 significant digits) and the summary (JSON). Each is written to a temporary
!> name unique to the writer and the pair is committed under a lock (write_outputs); on
!> any error no output file is left behind and earlier outputs of the name stay.
module fd_output
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_long, c_null_char
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real
   use fd_model, only: model_type, output_type, law_name, technique_name
   use fd_result, only: result_type
   use fd_record, only: record_info
   use fd_version, only: frictiondyn_version
   use fd_names, only: excitation_types
   use fd_matrices, only: modes_type, modes_flexible, modes_rigid, modes_unrestrained
   implicit none
   private

   public :: output_type, write_outputs, write_output_files, output_paths, temp_output_paths, summary_json, &
             history_header

   interface
      function c_mkdir(path, mode) bind(c, name='mkdir') result(stat)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int), value :: mode
         integer(c_int) :: stat
      end function c_mkdir
      function c_lock_acquire(path, fd) bind(c, name='fd_lock_acquire') result(err)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int), intent(out) :: fd
         integer(c_int) :: err
      end function c_lock_acquire
      function c_lock_release(path, fd) bind(c, name='fd_lock_release') result(err)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int), value :: fd
         integer(c_int) :: err
      end function c_lock_release
      function c_unlink(path) bind(c, name='fd_unlink') result(err)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int) :: err
      end function c_unlink
      function c_rename(old, new) bind(c, name='fd_rename') result(err)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: old(*), new(*)
         integer(c_int) :: err
      end function c_rename
      subroutine c_errno_text(err, buf, length) bind(c, name='fd_errno_text')
         import :: c_char, c_int
         integer(c_int), value :: err
         character(kind=c_char), intent(out) :: buf(*)
         integer(c_int), value :: length
      end subroutine c_errno_text
      function c_file_create(path, fd) bind(c, name='fd_file_create') result(err)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int), intent(out) :: fd
         integer(c_int) :: err
      end function c_file_create
      function c_file_write(fd, buf, length) bind(c, name='fd_file_write') result(err)
         import :: c_char, c_int, c_long
         integer(c_int), value :: fd
         character(kind=c_char), intent(in) :: buf(*)
         integer(c_long), value :: length
         integer(c_int) :: err
      end function c_file_write
      function c_file_close(fd) bind(c, name='fd_file_close') result(err)
         import :: c_int
         integer(c_int), value :: fd
         integer(c_int) :: err
      end function c_file_close
      function c_getpid() bind(c, name='fd_getpid') result(pid)
         import :: c_int
         integer(c_int) :: pid
      end function c_getpid
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

   !> A tag for temporary names: the process id and a random number (the names are also
   !> created exclusively, so two writers never share one).
   subroutine default_tag(tag)
      character(len=:), allocatable, intent(out) :: tag  !! e.g. '12345-3f9a0c1d'
      character(len=32) :: buf
      real(dp) :: r
      call random_number(r)
      write (buf, '(i0,"-",z8.8)') c_getpid(), int(r*2147483647.0_dp)
      tag = trim(buf)
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
   subroutine write_output_files(hist_path, summ_path, history, header, data, summary, error, tag)
      character(len=*), intent(in) :: hist_path           !! the history CSV
      character(len=*), intent(in) :: summ_path           !! the summary file
      logical, intent(in) :: history                      !! write the history
      character(len=*), intent(in) :: header              !! 'name[unit],...' of each column
      real(dp), intent(in) :: data(:, :)                  !! history (columns, samples)
      character(len=*), intent(in) :: summary             !! summary text (JSON)
      type(error_type), allocatable, intent(out) :: error !! cannot create, write or rename a file
      character(len=*), intent(in), optional :: tag       !! unique suffix of the temporary names
      character(len=:), allocatable :: htmp, stmp, mytag, lock, stem
      integer(c_int) :: err, fd
      integer :: attempt, ls

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
         if (present(tag) .or. error%stat /= eexist) return  ! the name exists (random clash)
      end do
      if (allocated(error)) return
      if (history) then
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
      if (err /= 0) then
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

   !> An error naming what failed and the system's reason (errno text).
   subroutine os_error(error, what, err)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: what
      integer(c_int), intent(in) :: err
      character(kind=c_char, len=256) :: buf
      call c_errno_text(err, buf, int(len(buf), c_int))
      call fatal_error(error, what//": "//buf(1:max(0, index(buf, c_null_char) - 1)))
   end subroutine os_error

   !> Create a directory and its missing parents.
   subroutine make_dir(dir, error)
      character(len=*), intent(in) :: dir
      type(error_type), allocatable, intent(out) :: error
      integer :: stat, i
      logical :: exists

      do i = 2, len(dir) + 1
         if (i <= len(dir)) then
            if (dir(i:i) /= '/') cycle
         end if
         inquire (file=dir(1:i - 1)//'/.', exist=exists)
         if (exists) cycle
         stat = c_mkdir(dir(1:i - 1)//c_null_char, int(o'755', c_int))
      end do
      inquire (file=dir//'/.', exist=exists)
      if (.not. exists) call fatal_error(error, "&output: cannot create the output directory dir = '"//dir//"'")
   end subroutine make_dir

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
      character(len=:), allocatable :: laws, esc
      integer :: d

      laws = ''
      do d = 1, model%n_devices
         laws = laws//'"'//trim(law_name(model%dev(d)%law))//'"'
         if (d < model%n_devices) laws = laws//', '
      end do
      call json_escape(deck_path, esc)
      js = '{'//nl
      js = js//'  "deck": "'//esc//'",'//nl
      js = js//'  "frictiondyn_version": "'//frictiondyn_version//'",'//nl
      if (present(record)) then
         if (allocated(record%path)) then
            js = js//'  "record": {'
            call json_escape(record%path, esc)
            js = js//'"file": "'//esc//'", "format": "'//trim(record%format)//'", "format_detected": '// &
                 trim(merge('true ', 'false', record%detected))//', "units": "'//trim(record%units)// &
                 '", "samples": '//trim(fmt_int(record%npts))//', "dt_s": '//trim(json_real(record%dt))// &
                 ', "scale": '//trim(json_real(record%scale))//', "peak_acc_mps2": '// &
                 trim(json_real(record%peak_acc))//', "sha256": "'//trim(record%sha256)//'"'
            if (allocated(record%title)) then
               call json_escape(record%title, esc)
               js = js//', "title": "'//esc//'"'
            end if
            js = js//'},'//nl
         end if
      end if
      call kv('n_dof', trim(fmt_int(res%n_dof)))
      call kv('n_devices', trim(fmt_int(res%n_devices)))
      call kv('technique', '"'//trim(technique_name(res%technique))//'"')
      js = js//'  "device_law": ['//laws//'],'//nl
      call kv('period_stuck_s', trim(json_real(res%period_stuck)))
      call kv('xi_stuck', trim(json_real(res%xi_stuck)))
      call kv('dt1_s', trim(json_real(res%dt1)))
      call kv('dt2_s', trim(json_real(res%dt2)))
      call kv('dt_min_s', trim(json_real(res%dt_min)))
      call kr('peak_u_m', res%peak_u)
      call kr('peak_u_time_s', res%peak_u_time)
      call kr('peak_v_mps', res%peak_v)
      call kr('peak_aabs_mps2', res%peak_aabs)
      call kr('peak_aabs_time_s', res%peak_aabs_time)
      call kr('peak_s_m', res%peak_s)
      call kr('peak_force_N', res%peak_force)
      call ki('stick_to_slip', res%stick_to_slip)
      call ki('slip_to_stick', res%slip_to_stick)
      call ki('slip_reversals', res%reversals)
      call kv('steps_dt1', trim(fmt_int(res%steps_dt1)))
      call kv('steps_dt2', trim(fmt_int(res%steps_dt2)))
      call kv('steps_finer', trim(fmt_int(res%steps_finer)))
      call kv('factorizations', trim(fmt_int(res%factorizations)))
      call kv('events', trim(fmt_int(res%events)))
      if (res%exact_peaks) then
         ! the exact technique: peaks are the exact extrema; its event times, accumulations
         call kv('peaks_exact', 'true')
         call kr('event_times_s', res%event_time(1:res%n_event_times))
         call kv('accumulation_points', trim(fmt_int(res%accumulations)))
         call kr('accumulation_times_s', res%accumulation_time(1:res%n_accumulation_times))
      end if
      call kv('patterns_solved', trim(fmt_int(res%patterns)))
      call kv('lcp_fallbacks', trim(fmt_int(res%lcp_fallbacks)))
      call kv('correctness_violations', trim(fmt_int(res%violations)))
      call kr('violation_times_s', res%violation_time(1:res%n_violation_times))
      call ki('violation_devices', res%violation_device(1:res%n_violation_times))
      call kv('energy_input_J', trim(json_real(res%e_input)))
      call kv('energy_kinetic_J', trim(json_real(res%e_kinetic)))
      call kv('energy_strain_J', trim(json_real(res%e_strain)))
      call kv('energy_viscous_J', trim(json_real(res%e_viscous)))
      call kv('energy_friction_J', trim(json_real(res%e_friction)))
      call kv('energy_device_elastic_J', trim(json_real(res%e_device)))
      call kv('energy_residual_J', trim(json_real(res%e_residual)))
      call engineering_keys()
      call kv('samples', trim(fmt_int(res%nout)))
      js = js//'  "run_time_s": '//trim(json_real(res%run_time))//nl//'}'
   contains
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
            call kv('excitation_frequency_Hz', trim(json_real(eng%frequency)))
            call kv('duration_s', trim(json_real(eng%duration)))
            call ks('dof_labels', eng%dof_label)
            call ks('device_labels', eng%device_label)
            call kv('damping_a0_per_s', trim(json_real(eng%a0)))
            call kv('damping_a1_s', trim(json_real(eng%a1)))
            call modes_keys('stuck', eng%stuck)
            call modes_keys('free', eng%free)
            call kr('residual_s_m', eng%residual_s)
            call kv('peak_base_shear_N', trim(json_real(eng%peak_shear(0))))
            call kv('peak_base_shear_time_s', trim(json_real(eng%peak_shear_time(0))))
            call kv('residual_base_shear_N', trim(json_real(eng%shear(0))))
            call kv('n_storeys', trim(fmt_int(eng%n_storeys)))
            call ks('storey_labels', eng%storey_label)
            js = js//'  "storey_nodes": ['
            do i = 1, eng%n_storeys
               js = js//'['//trim(fmt_int(eng%storey_i(i)))//', '//trim(fmt_int(eng%storey_j(i)))//']'
               if (i < eng%n_storeys) js = js//', '
            end do
            js = js//'],'//nl
            call kr('storey_height_m', eng%height)
            call kr('peak_drift_m', eng%peak_drift)
            call kr('peak_drift_time_s', eng%peak_drift_time)
            call kr('residual_drift_m', eng%drift)
            allocate (ratio(eng%n_storeys))
            ratio = 0.0_dp
            where (eng%height > 0.0_dp) ratio = eng%peak_drift/eng%height
            call kr('peak_drift_ratio', ratio)
            where (eng%height > 0.0_dp) ratio = eng%drift/eng%height
            call kr('residual_drift_ratio', ratio)
            call kr('peak_storey_shear_N', eng%peak_shear(1:))
            call kr('peak_storey_shear_time_s', eng%peak_shear_time(1:))
            call kr('residual_storey_shear_N', eng%shear(1:))
         end associate
      end subroutine engineering_keys
      !> The modes of one system: status, periods (0: a rigid-body mode), shapes, mass ratios, damping.
      subroutine modes_keys(name, m)
         character(len=*), intent(in) :: name
         type(modes_type), intent(in) :: m
         character(len=:), allocatable :: list
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
            js = js//'  "mode_shapes_'//name//'": [],'//nl
            call kr('modal_mass_ratio_'//name, [real(dp) ::])
            call kr('modal_xi_'//name, [real(dp) ::])
            return
         end select
         ! a rigid-body mode (w = 0): period and damping ratio 0 (its period is infinite)
         call kr('periods_'//name//'_s', merge(m%period, 0.0_dp, m%omega2 > 0.0_dp))
         js = js//'  "mode_shapes_'//name//'": ['
         do j = 1, m%n
            call json_list(m%shape(:, j), list)
            js = js//list
            if (j < m%n) js = js//', '
         end do
         js = js//'],'//nl
         call kr('modal_mass_ratio_'//name, m%mass_ratio)
         call kr('modal_xi_'//name, merge(m%xi, 0.0_dp, m%omega2 > 0.0_dp))
      end subroutine modes_keys
      !> Strings.
      subroutine ks(key, x)
         character(len=*), intent(in) :: key
         character(len=*), intent(in) :: x(:)
         integer :: k
         character(len=:), allocatable :: e
         js = js//'  "'//key//'": ['
         do k = 1, size(x)
            call json_escape(trim(x(k)), e)
            js = js//'"'//e//'"'
            if (k < size(x)) js = js//', '
         end do
         js = js//'],'//nl
      end subroutine ks
      subroutine kv(key, val)
         character(len=*), intent(in) :: key, val
         js = js//'  "'//key//'": '//val//','//nl
      end subroutine kv
      subroutine kr(key, x)
         character(len=*), intent(in) :: key
         real(dp), intent(in) :: x(:)
         character(len=:), allocatable :: list
         call json_list(x, list)
         js = js//'  "'//key//'": '//list//','//nl
      end subroutine kr
      subroutine ki(key, x)
         character(len=*), intent(in) :: key
         integer, intent(in) :: x(:)
         integer :: k
         js = js//'  "'//key//'": ['
         do k = 1, size(x)
            js = js//trim(fmt_int(x(k)))
            if (k < size(x)) js = js//', '
         end do
         js = js//'],'//nl
      end subroutine ki
   end subroutine summary_json

   !> The header line of the history: name[unit] of each column, comma separated.
   pure subroutine history_header(res, line)
      type(result_type), intent(in) :: res                 !! the result
      character(len=:), allocatable, intent(out) :: line   !! the header
      integer :: j

      line = ''
      do j = 1, res%ncol
         line = line//trim(res%names(j))//'['//trim(res%units(j))//']'
         if (j < res%ncol) line = line//','
      end do
   end subroutine history_header

   !> A list of reals as JSON, '[x1, x2, ...]', built in one buffer (appending number by
   !> number to a growing string copies it each time: quadratic for long lists).
   pure subroutine json_list(x, text)
      real(dp), intent(in) :: x(:)
      character(len=:), allocatable, intent(out) :: text
      character(len=:), allocatable :: buf
      character(len=32) :: item
      integer :: k, n, l

      allocate (character(len=2 + 34*size(x)) :: buf)
      buf(1:1) = '['
      n = 1
      do k = 1, size(x)
         item = json_real(x(k))
         l = len_trim(item)
         buf(n + 1:n + l) = item(1:l)
         n = n + l
         if (k < size(x)) then
            buf(n + 1:n + 2) = ', '
            n = n + 2
         end if
      end do
      text = buf(1:n)//']'
   end subroutine json_list

   !> A real as JSON: 17 significant digits (null when not finite), left-adjusted.
   pure function json_real(x) result(str)
      use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
      real(dp), intent(in) :: x
      character(len=32) :: str
      if (.not. ieee_is_finite(x)) then
         str = 'null'
         return
      end if
      write (str, '(es24.16e3)') x
      str = adjustl(str)
   end function json_real

   pure subroutine json_escape(s, r)
      character(len=*), intent(in) :: s
      character(len=:), allocatable, intent(out) :: r
      integer :: i
      r = ''
      do i = 1, len(s)
         if (s(i:i) == '"' .or. s(i:i) == '\') then
            r = r//'\'//s(i:i)
         else if (iachar(s(i:i)) < 32) then
            r = r//' '
         else
            r = r//s(i:i)
         end if
      end do
   end subroutine json_escape

end module fd_output
