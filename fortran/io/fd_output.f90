!> Output files of a run: the time-history CSV (a header naming every column with its
!> unit, 17 significant digits) and the summary (JSON). Each is written to a temporary
!> name and renamed when complete; on any error no output file is left behind.
module fd_output
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_null_char
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real
   use fd_model, only: model_type, output_type, law_name, technique_name
   use fd_result, only: result_type
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
      call kv('samples', trim(fmt_int(res%nout)))
      js = js//'  "run_time_s": '//trim(json_real(res%run_time))//nl//'}'
   contains
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
