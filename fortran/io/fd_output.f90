!> Output files of a run: the time-history CSV (a header naming every column with its
!> unit, 17 significant digits) and the summary (JSON). Each is written to a temporary
!> name and renamed when complete; on any error no output file is left behind.
module fd_output
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_null_char
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real
   use fd_model, only: model_type, output_type, law_name, technique_name
   use fd_result, only: result_type
   use fd_version, only: frictiondyn_version
   use fd_names, only: excitation_types, mode_systems
   use fd_matrices, only: modes_type, modes_none, modes_flexible, modes_rigid, modes_unrestrained
   implicit none
   private

   public :: output_type, write_outputs, write_output_files, output_paths, summary_json, history_header

   interface
      function c_rename(old, new) bind(c, name='rename') result(stat)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: old(*), new(*)
         integer(c_int) :: stat
      end function c_rename
      function c_mkdir(path, mode) bind(c, name='mkdir') result(stat)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int), value :: mode
         integer(c_int) :: stat
      end function c_mkdir
   end interface

contains

   !> Paths of the time-history CSV and of the summary file.
   pure subroutine output_paths(out, hist, summ)
      type(output_type), intent(in) :: out                  !! output settings
      character(len=:), allocatable, intent(out) :: hist    !! the CSV file
      character(len=:), allocatable, intent(out) :: summ    !! the JSON file
      hist = out%dir//'/'//out%name//'.csv'
      summ = out%dir//'/'//out%name//'.summary.json'
   end subroutine output_paths

   !> Write the history and the summary into out%dir (created when missing); nothing is left
   !> behind on failure.
   subroutine write_outputs(out, model, res, deck_path, error)
      type(output_type), intent(in) :: out                !! output settings
      type(model_type), intent(in) :: model               !! the model run
      type(result_type), intent(in) :: res                !! its result
      character(len=*), intent(in) :: deck_path           !! deck, named in the summary
      type(error_type), allocatable, intent(out) :: error !! cannot create or write a file
      character(len=:), allocatable :: hist, summ, header, js

      call make_dir(out%dir, error)
      if (allocated(error)) return
      call output_paths(out, hist, summ)
      call history_header(res, header)
      call summary_json(model, res, deck_path, js)
      call write_output_files(hist, summ, out%history, header, res%hist, js, error)
   end subroutine write_outputs

   !> Write a history (when `history`: its header line, then one row per sample) to
   !> `hist_path` and a summary text to `summ_path`, each to a temporary name renamed when
   !> complete; nothing is left behind on failure. The one writer of output files: the
   !> executable's outputs and those of the Python package go through it.
   subroutine write_output_files(hist_path, summ_path, history, header, data, summary, error)
      character(len=*), intent(in) :: hist_path           !! the history CSV
      character(len=*), intent(in) :: summ_path           !! the summary file
      logical, intent(in) :: history                      !! write the history
      character(len=*), intent(in) :: header              !! 'name[unit],...' of each column
      real(dp), intent(in) :: data(:, :)                  !! history (columns, samples)
      character(len=*), intent(in) :: summary             !! summary text (JSON)
      type(error_type), allocatable, intent(out) :: error !! cannot create or write a file
      character(len=:), allocatable :: hist, summ
      integer :: stat

      hist = hist_path
      summ = summ_path
      if (history) then
         call write_history(hist//'.tmp', header, data, error)
         if (allocated(error)) return
      end if
      call write_summary(summ//'.tmp', summary, error)
      if (allocated(error)) then
         if (history) call remove(hist//'.tmp')
         return
      end if
      if (history) then
         stat = c_rename(hist//'.tmp'//c_null_char, hist//c_null_char)
         if (stat /= 0) then
            call remove(hist//'.tmp'); call remove(summ//'.tmp')
            call fatal_error(error, "cannot rename '"//hist//".tmp' to '"//hist//"'")
            return
         end if
      end if
      stat = c_rename(summ//'.tmp'//c_null_char, summ//c_null_char)
      if (stat /= 0) then
         if (history) call remove(hist)
         call remove(summ//'.tmp')
         call fatal_error(error, "cannot rename '"//summ//".tmp' to '"//summ//"'")
      end if
   end subroutine write_output_files

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

   subroutine remove(path)
      character(len=*), intent(in) :: path
      integer :: unit, ios
      open (newunit=unit, file=path, status='old', iostat=ios)
      if (ios == 0) close (unit, status='delete')
   end subroutine remove

   subroutine write_history(path, header, data, error)
      character(len=*), intent(in) :: path
      character(len=*), intent(in) :: header
      real(dp), intent(in) :: data(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer :: unit, ios, i
      character(len=512) :: msg
      character(len=:), allocatable :: fmt

      open (newunit=unit, file=path, status='replace', action='write', iostat=ios, iomsg=msg)
      if (ios /= 0) then
         call fatal_error(error, "cannot create '"//path//"': "//trim(msg))
         return
      end if
      write (unit, '(a)', iostat=ios) header
      fmt = '('//trim(fmt_int(size(data, 1)))//'(es24.16e3,:,","))'
      do i = 1, size(data, 2)
         write (unit, fmt, iostat=ios, iomsg=msg) data(:, i)
         if (ios /= 0) exit
      end do
      if (ios /= 0) then
         close (unit, status='delete')
         call fatal_error(error, "cannot write '"//path//"': "//trim(msg))
         return
      end if
      close (unit)
   end subroutine write_history

   subroutine write_summary(path, js, error)
      character(len=*), intent(in) :: path
      character(len=*), intent(in) :: js
      type(error_type), allocatable, intent(out) :: error
      integer :: unit, ios
      character(len=512) :: msg

      open (newunit=unit, file=path, status='replace', action='write', iostat=ios, iomsg=msg)
      if (ios /= 0) then
         call fatal_error(error, "cannot create '"//path//"': "//trim(msg))
         return
      end if
      write (unit, '(a)', iostat=ios, iomsg=msg) js
      if (ios /= 0) then
         close (unit, status='delete')
         call fatal_error(error, "cannot write '"//path//"': "//trim(msg))
         return
      end if
      close (unit)
   end subroutine write_summary

   !> The summary of a run as a JSON object (keys documented in docs/namelist.md).
   subroutine summary_json(model, res, deck_path, js)
      type(model_type), intent(in) :: model                !! the model run
      type(result_type), intent(in) :: res                 !! its result
      character(len=*), intent(in) :: deck_path            !! deck named in the summary
      character(len=:), allocatable, intent(out) :: js     !! the JSON text
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
      call kv('n_dof', trim(fmt_int(res%n_dof)))
      call kv('n_devices', trim(fmt_int(res%n_devices)))
      call kv('technique', '"'//trim(technique_name(res%technique))//'"')
      js = js//'  "device_law": ['//laws//'],'//nl
      call kv('period_stuck_s', trim(json_defined(res%period_stuck, res%period_stuck > 0.0_dp)))
      call kv('xi_stuck', trim(json_defined(res%xi_stuck, res%period_stuck > 0.0_dp)))
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
         if (allocated(model%record_file)) then
            call json_escape(model%record_file, esc)
            call kv('record_file', '"'//esc//'"')
            call kv('record_sha256', '"'//trim(model%record_sha256)//'"')
         else
            call kv('record_file', 'null')
            call kv('record_sha256', 'null')
         end if
         associate (eng => res%eng)
            if (eng%excitation >= 1 .and. eng%excitation <= size(excitation_types)) then
               call kv('excitation_type', '"'//trim(excitation_types(eng%excitation)%name)//'"')
            else
               call kv('excitation_type', 'null')
            end if
            call kv('excitation_frequency_Hz', trim(json_defined(eng%frequency, eng%frequency > 0.0_dp)))
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
            call kd('storey_height_m', eng%height, eng%height > 0.0_dp)
            call kr('peak_drift_m', eng%peak_drift)
            call kr('peak_drift_time_s', eng%peak_drift_time)
            call kr('residual_drift_m', eng%drift)
            allocate (ratio(eng%n_storeys))
            ratio = 0.0_dp
            where (eng%height > 0.0_dp) ratio = eng%peak_drift/eng%height
            call kd('peak_drift_ratio', ratio, eng%height > 0.0_dp)
            where (eng%height > 0.0_dp) ratio = eng%drift/eng%height
            call kd('residual_drift_ratio', ratio, eng%height > 0.0_dp)
            call kr('peak_storey_shear_N', eng%peak_shear(1:))
            call kr('peak_storey_shear_time_s', eng%peak_shear_time(1:))
            call kr('residual_storey_shear_N', eng%shear(1:))
         end associate
      end subroutine engineering_keys
      !> The modes of one system: status, periods (null: infinite), shapes, mass ratios, damping.
      subroutine modes_keys(name, m)
         character(len=*), intent(in) :: name
         type(modes_type), intent(in) :: m
         integer :: j, i
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
         call kr('periods_'//name//'_s', m%period)
         js = js//'  "mode_shapes_'//name//'": ['
         do j = 1, m%n
            js = js//'['
            do i = 1, size(m%shape, 1)
               js = js//trim(json_real(m%shape(i, j)))
               if (i < size(m%shape, 1)) js = js//', '
            end do
            js = js//']'
            if (j < m%n) js = js//', '
         end do
         js = js//'],'//nl
         call kr('modal_mass_ratio_'//name, m%mass_ratio)
         call kr('modal_xi_'//name, m%xi)
      end subroutine modes_keys
      !> Reals, null where not defined.
      subroutine kd(key, x, defined)
         character(len=*), intent(in) :: key
         real(dp), intent(in) :: x(:)
         logical, intent(in) :: defined(:)
         integer :: k
         js = js//'  "'//key//'": ['
         do k = 1, size(x)
            js = js//trim(json_defined(x(k), defined(k)))
            if (k < size(x)) js = js//', '
         end do
         js = js//'],'//nl
      end subroutine kd
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
         integer :: k
         js = js//'  "'//key//'": ['
         do k = 1, size(x)
            js = js//trim(json_real(x(k)))
            if (k < size(x)) js = js//', '
         end do
         js = js//'],'//nl
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

   !> A real as JSON when it is defined, else null.
   pure function json_defined(x, defined) result(str)
      real(dp), intent(in) :: x
      logical, intent(in) :: defined
      character(len=32) :: str
      str = 'null'
      if (defined) str = json_real(x)
   end function json_defined

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
         if (s(i:i) == '"' .or. s(i:i) == '\') r = r//'\'
         r = r//s(i:i)
      end do
   end subroutine json_escape

end module fd_output
