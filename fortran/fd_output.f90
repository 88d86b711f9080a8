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

   public :: output_type, write_outputs, history_path, summary_path

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
      integer :: unit, ios, i, j
      character(len=512) :: msg
      character(len=:), allocatable :: fmt

      open (newunit=unit, file=path, status='replace', action='write', iostat=ios, iomsg=msg)
      if (ios /= 0) then
         call fatal_error(error, "cannot create '"//path//"': "//trim(msg))
         return
      end if
      do j = 1, res%ncol
         write (unit, '(a)', advance='no', iostat=ios) trim(res%names(j))//'['//trim(res%units(j))//']'
         if (j < res%ncol) write (unit, '(a)', advance='no', iostat=ios) ','
      end do
      write (unit, '(a)', iostat=ios) ''
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
      integer :: unit, ios, d
      character(len=512) :: msg
      character(len=:), allocatable :: laws

      open (newunit=unit, file=path, status='replace', action='write', iostat=ios, iomsg=msg)
      if (ios /= 0) then
         call fatal_error(error, "cannot create '"//path//"': "//trim(msg))
         return
      end if
      laws = ''
      do d = 1, model%n_devices
         laws = laws//'"'//law_name(model%dev(d)%law)//'"'
         if (d < model%n_devices) laws = laws//', '
      end do
      write (unit, '(a)', iostat=ios) '{'
      call kv_s('deck', json_escape(deck_path))
      call kv_i('n_dof', res%n_dof)
      call kv_i('n_devices', res%n_devices)
      write (unit, '(a)', iostat=ios) '  "device_law": ['//laws//'],'
      call kv_r('period_stuck_s', res%period_stuck)
      call kv_r('xi_stuck', res%xi_stuck)
      call kv_r('dt1_s', res%dt1)
      call kv_r('dt2_s', res%dt2)
      call kv_r('dt_min_s', res%dt_min)
      call kv_ra('peak_u_m', res%peak_u)
      call kv_ra('peak_u_time_s', res%peak_u_time)
      call kv_ra('peak_v_mps', res%peak_v)
      call kv_ra('peak_aabs_mps2', res%peak_aabs)
      call kv_ra('peak_aabs_time_s', res%peak_aabs_time)
      call kv_ra('peak_s_m', res%peak_s)
      call kv_ra('peak_force_N', res%peak_force)
      call kv_ia('stick_to_slip', res%stick_to_slip)
      call kv_ia('slip_to_stick', res%slip_to_stick)
      call kv_ia('slip_reversals', res%reversals)
      call kv_i('steps_dt1', res%steps_dt1)
      call kv_i('steps_dt2', res%steps_dt2)
      call kv_i('steps_finer', res%steps_finer)
      call kv_i('factorizations', res%factorizations)
      call kv_i('correctness_violations', res%violations)
      call kv_ra('violation_times_s', res%violation_time(1:res%n_violation_times))
      call kv_ia('violation_devices', res%violation_device(1:res%n_violation_times))
      call kv_r('energy_input_J', res%e_input)
      call kv_r('energy_kinetic_J', res%e_kinetic)
      call kv_r('energy_strain_J', res%e_strain)
      call kv_r('energy_viscous_J', res%e_viscous)
      call kv_r('energy_friction_J', res%e_friction)
      call kv_r('energy_device_elastic_J', res%e_device)
      call kv_r('energy_residual_J', res%e_residual)
      call kv_i('samples', res%nout)
      write (unit, '(a)', iostat=ios) '  "run_time_s": '//fmt_real(res%run_time)
      write (unit, '(a)', iostat=ios, iomsg=msg) '}'
      if (ios /= 0) then
         close (unit, status='delete')
         call fatal_error(error, "cannot write '"//path//"': "//trim(msg))
         return
      end if
      close (unit)
   contains
      subroutine kv_s(key, val)
         character(len=*), intent(in) :: key, val
         write (unit, '(a)', iostat=ios) '  "'//key//'": "'//val//'",'
      end subroutine kv_s
      subroutine kv_i(key, val)
         character(len=*), intent(in) :: key
         integer, intent(in) :: val
         write (unit, '(a)', iostat=ios) '  "'//key//'": '//fmt_int(val)//','
      end subroutine kv_i
      subroutine kv_r(key, val)
         character(len=*), intent(in) :: key
         real(dp), intent(in) :: val
         write (unit, '(a)', iostat=ios) '  "'//key//'": '//json_real(val)//','
      end subroutine kv_r
      subroutine kv_ra(key, val)
         character(len=*), intent(in) :: key
         real(dp), intent(in) :: val(:)
         integer :: k
         write (unit, '(a)', advance='no', iostat=ios) '  "'//key//'": ['
         do k = 1, size(val)
            write (unit, '(a)', advance='no', iostat=ios) json_real(val(k))
            if (k < size(val)) write (unit, '(a)', advance='no', iostat=ios) ', '
         end do
         write (unit, '(a)', iostat=ios) '],'
      end subroutine kv_ra
      subroutine kv_ia(key, val)
         character(len=*), intent(in) :: key
         integer, intent(in) :: val(:)
         integer :: k
         write (unit, '(a)', advance='no', iostat=ios) '  "'//key//'": ['
         do k = 1, size(val)
            write (unit, '(a)', advance='no', iostat=ios) fmt_int(val(k))
            if (k < size(val)) write (unit, '(a)', advance='no', iostat=ios) ', '
         end do
         write (unit, '(a)', iostat=ios) '],'
      end subroutine kv_ia
   end subroutine write_summary

   !> A real as JSON: 17 significant digits.
   pure function json_real(x) result(str)
      real(dp), intent(in) :: x
      character(len=:), allocatable :: str
      character(len=32) :: buf
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
