!> Output files of a run: the time-history CSV (a header naming every column with its
!> unit, 17 significant digits) and the summary (JSON). Each is written to a temporary
!> name and renamed when complete; on any error no output file is left behind.
module fd_output
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_null_char
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real
   use fd_model, only: model_type, law_name
   use fd_result, only: result_type
   implicit none
   private

   public :: output_type, write_outputs, history_path, summary_path, summary_json, history_header

   !> Where and what to write.
   type :: output_type
      character(len=:), allocatable :: dir   !! output directory (created if missing)
      character(len=:), allocatable :: name  !! base name of the files
      logical :: history = .true.            !! write the time-history CSV
   end type output_type

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

   !> Path of the time-history CSV.
   pure function history_path(out) result(path)
      type(output_type), intent(in) :: out    !! output settings
      character(len=:), allocatable :: path   !! the CSV file
      path = out%dir//'/'//out%name//'.csv'
   end function history_path

   !> Path of the summary file.
   pure function summary_path(out) result(path)
      type(output_type), intent(in) :: out    !! output settings
      character(len=:), allocatable :: path   !! the JSON file
      path = out%dir//'/'//out%name//'.summary.json'
   end function summary_path

   !> Write the history and the summary; nothing is left behind on failure.
   subroutine write_outputs(out, model, res, deck_path, error)
      type(output_type), intent(in) :: out                !! output settings
      type(model_type), intent(in) :: model               !! the model run
      type(result_type), intent(in) :: res                !! its result
      character(len=*), intent(in) :: deck_path           !! deck, named in the summary
      type(error_type), allocatable, intent(out) :: error !! cannot create or write a file
      character(len=:), allocatable :: hist, summ
      integer :: stat

      call make_dir(out%dir, error)
      if (allocated(error)) return
      hist = history_path(out)
      summ = summary_path(out)
      if (out%history) then
         call write_history(hist//'.tmp', res, error)
         if (allocated(error)) return
      end if
      call write_summary(summ//'.tmp', model, res, deck_path, error)
      if (allocated(error)) then
         if (out%history) call remove(hist//'.tmp')
         return
      end if
      if (out%history) then
         stat = c_rename(hist//'.tmp'//c_null_char, hist//c_null_char)
         if (stat /= 0) then
            call remove(hist//'.tmp'); call remove(summ//'.tmp')
            call fatal_error(error, "cannot rename '"//hist//".tmp' to '"//hist//"'")
            return
         end if
      end if
      stat = c_rename(summ//'.tmp'//c_null_char, summ//c_null_char)
      if (stat /= 0) then
         if (out%history) call remove(hist)
         call remove(summ//'.tmp')
         call fatal_error(error, "cannot rename '"//summ//".tmp' to '"//summ//"'")
      end if
   end subroutine write_outputs

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

   subroutine write_history(path, res, error)
      character(len=*), intent(in) :: path
      type(result_type), intent(in) :: res
      type(error_type), allocatable, intent(out) :: error
      integer :: unit, ios, i
      character(len=512) :: msg
      character(len=:), allocatable :: fmt

      open (newunit=unit, file=path, status='replace', action='write', iostat=ios, iomsg=msg)
      if (ios /= 0) then
         call fatal_error(error, "cannot create '"//path//"': "//trim(msg))
         return
      end if
      write (unit, '(a)', iostat=ios) history_header(res)
      fmt = '('//fmt_int(res%ncol)//'(es24.16e3,:,","))'
      do i = 1, res%nout
         write (unit, fmt, iostat=ios, iomsg=msg) res%hist(:, i)
         if (ios /= 0) exit
      end do
      if (ios /= 0) then
         close (unit, status='delete')
         call fatal_error(error, "cannot write '"//path//"': "//trim(msg))
         return
      end if
      close (unit)
   end subroutine write_history

   subroutine write_summary(path, model, res, deck_path, error)
      character(len=*), intent(in) :: path
      type(model_type), intent(in) :: model
      type(result_type), intent(in) :: res
      character(len=*), intent(in) :: deck_path
      type(error_type), allocatable, intent(out) :: error
      integer :: unit, ios
      character(len=512) :: msg

      open (newunit=unit, file=path, status='replace', action='write', iostat=ios, iomsg=msg)
      if (ios /= 0) then
         call fatal_error(error, "cannot create '"//path//"': "//trim(msg))
         return
      end if
      write (unit, '(a)', iostat=ios, iomsg=msg) summary_json(model, res, deck_path)
      if (ios /= 0) then
         close (unit, status='delete')
         call fatal_error(error, "cannot write '"//path//"': "//trim(msg))
         return
      end if
      close (unit)
   end subroutine write_summary

   !> The summary of a run as a JSON object (keys documented in docs/namelist.md).
   pure function summary_json(model, res, deck_path) result(js)
      type(model_type), intent(in) :: model        !! the model run
      type(result_type), intent(in) :: res         !! its result
      character(len=*), intent(in) :: deck_path    !! deck named in the summary
      character(len=:), allocatable :: js          !! the JSON text
      character(len=:), allocatable :: laws
      character(len=1), parameter :: nl = achar(10)
      integer :: d

      laws = ''
      do d = 1, model%n_devices
         laws = laws//'"'//law_name(model%dev(d)%law)//'"'
         if (d < model%n_devices) laws = laws//', '
      end do
      js = '{'//nl
      js = js//'  "deck": "'//json_escape(deck_path)//'",'//nl
      js = js//kv('n_dof', fmt_int(res%n_dof))//kv('n_devices', fmt_int(res%n_devices))
      js = js//'  "device_law": ['//laws//'],'//nl
      js = js//kv('period_stuck_s', json_real(res%period_stuck))//kv('xi_stuck', json_real(res%xi_stuck))
      js = js//kv('dt1_s', json_real(res%dt1))//kv('dt2_s', json_real(res%dt2))// &
           kv('dt_min_s', json_real(res%dt_min))
      js = js//kv('peak_u_m', reals(res%peak_u))//kv('peak_u_time_s', reals(res%peak_u_time))
      js = js//kv('peak_v_mps', reals(res%peak_v))//kv('peak_aabs_mps2', reals(res%peak_aabs))
      js = js//kv('peak_aabs_time_s', reals(res%peak_aabs_time))
      js = js//kv('peak_s_m', reals(res%peak_s))//kv('peak_force_N', reals(res%peak_force))
      js = js//kv('stick_to_slip', ints(res%stick_to_slip))//kv('slip_to_stick', ints(res%slip_to_stick))
      js = js//kv('slip_reversals', ints(res%reversals))
      js = js//kv('steps_dt1', fmt_int(res%steps_dt1))//kv('steps_dt2', fmt_int(res%steps_dt2))
      js = js//kv('steps_finer', fmt_int(res%steps_finer))//kv('factorizations', fmt_int(res%factorizations))
      js = js//kv('events', fmt_int(res%events))
      js = js//kv('correctness_violations', fmt_int(res%violations))
      js = js//kv('violation_times_s', reals(res%violation_time(1:res%n_violation_times)))
      js = js//kv('violation_devices', ints(res%violation_device(1:res%n_violation_times)))
      js = js//kv('energy_input_J', json_real(res%e_input))//kv('energy_kinetic_J', json_real(res%e_kinetic))
      js = js//kv('energy_strain_J', json_real(res%e_strain))//kv('energy_viscous_J', json_real(res%e_viscous))
      js = js//kv('energy_friction_J', json_real(res%e_friction))
      js = js//kv('energy_device_elastic_J', json_real(res%e_device))
      js = js//kv('energy_residual_J', json_real(res%e_residual))
      js = js//kv('samples', fmt_int(res%nout))
      js = js//'  "run_time_s": '//json_real(res%run_time)//nl//'}'
   contains
      pure function kv(key, val) result(line)
         character(len=*), intent(in) :: key, val
         character(len=:), allocatable :: line
         line = '  "'//key//'": '//val//','//nl
      end function kv
      pure function reals(x) result(str)
         real(dp), intent(in) :: x(:)
         character(len=:), allocatable :: str
         integer :: k
         str = '['
         do k = 1, size(x)
            str = str//json_real(x(k))
            if (k < size(x)) str = str//', '
         end do
         str = str//']'
      end function reals
      pure function ints(x) result(str)
         integer, intent(in) :: x(:)
         character(len=:), allocatable :: str
         integer :: k
         str = '['
         do k = 1, size(x)
            str = str//fmt_int(x(k))
            if (k < size(x)) str = str//', '
         end do
         str = str//']'
      end function ints
   end function summary_json

   !> The header line of the history: name[unit] of each column, comma separated.
   pure function history_header(res) result(line)
      type(result_type), intent(in) :: res     !! the result
      character(len=:), allocatable :: line    !! the header
      integer :: j

      line = ''
      do j = 1, res%ncol
         line = line//trim(res%names(j))//'['//trim(res%units(j))//']'
         if (j < res%ncol) line = line//','
      end do
   end function history_header

   !> A real as JSON: 17 significant digits.
   pure function json_real(x) result(str)
      use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
      real(dp), intent(in) :: x
      character(len=:), allocatable :: str
      character(len=32) :: buf
      if (.not. ieee_is_finite(x)) then
         str = 'null'
         return
      end if
      write (buf, '(es24.16e3)') x
      str = trim(adjustl(buf))
   end function json_real

   pure function json_escape(s) result(r)
      character(len=*), intent(in) :: s
      character(len=:), allocatable :: r
      integer :: i
      r = ''
      do i = 1, len(s)
         if (s(i:i) == '"' .or. s(i:i) == '\') r = r//'\'
         r = r//s(i:i)
      end do
   end function json_escape

end module fd_output
