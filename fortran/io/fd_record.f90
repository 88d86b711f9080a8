!> Reader of recorded table motion. Three formats: PEER NGA `.AT2` (four header lines, NPTS
!> and DT on the fourth, several values a line), one value a line, or time-value columns.
!> Parsing is strict: every value is a plain decimal number (no Fortran list-directed
!> tokens such as '/', 'r*' or '*'), a line with no value is an error, the count of values
!> must match NPTS; every message names the file, the line and what was expected. Values
!> are converted with C strtod (correctly rounded), one pass over the file read at once.
!> Displacement records are turned into accelerations by second differences.
module fd_record
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
   use, intrinsic :: iso_c_binding, only: c_char, c_double, c_ptr, c_null_ptr, c_null_char
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real, fmt_text, stat_no_memory
   use fd_textio, only: read_file_text, lower
   use fd_sha256, only: sha256_text
   implicit none
   private

   public :: record_info, read_record, parse_real, units_factor, standard_gravity
   public :: npts_dt, field_width, misplaced_field
   public :: record_formats, record_units_list

   real(dp), parameter :: standard_gravity = 9.80665_dp  !! g [m/s2] (CGPM 1901)
   !> The valid values of record_format.
   character(len=*), parameter :: record_formats = "'auto', 'at2', 'values', 'time_value'"
   !> The valid values of record_units.
   character(len=*), parameter :: record_units_list = &
      "'g', 'm/s2', 'cm/s2' (= 'gal'), 'mm/s2' (acceleration); 'm', 'cm', 'mm' (displacement)"

   integer, parameter :: num_ok = 0, num_syntax = 1, num_nan = 2, num_infinite = 3

   !> A unit a record's values may be in: its name (lower case), its factor to SI and its kind.
   type :: unit_type
      character(len=5) :: name = ''         !! as record_units writes it
      real(dp) :: factor = 1.0_dp           !! to m/s2 or m
      logical :: displacement = .false.     !! a displacement's (else an acceleration's)
   end type unit_type

   !> The units of record_units_list.
   type(unit_type), parameter :: unit_table(*) = [ &
      unit_type('g', standard_gravity, .false.), unit_type('m/s2', 1.0_dp, .false.), &
      unit_type('cm/s2', 1.0e-2_dp, .false.), unit_type('gal', 1.0e-2_dp, .false.), &
      unit_type('mm/s2', 1.0e-3_dp, .false.), unit_type('m', 1.0_dp, .true.), &
      unit_type('cm', 1.0e-2_dp, .true.), unit_type('mm', 1.0e-3_dp, .true.)]

   !> What was read from a record file (named in the summary).
   type :: record_info
      character(len=:), allocatable :: path    !! the file read
      character(len=16) :: format = ''         !! 'at2', 'values' or 'time_value'
      logical :: detected = .false.            !! format chosen by record_format = 'auto'
      character(len=16) :: units = ''          !! units of the file's values
      integer :: npts = 0                      !! samples read
      real(dp) :: dt = 0.0_dp                  !! sampling step [s]
      real(dp) :: scale = 1.0_dp               !! record_scale applied
      real(dp) :: peak_acc = 0.0_dp            !! max |table acceleration| fed to the run [m/s2]
      character(len=:), allocatable :: title   !! AT2: header lines 1 and 2
      character(len=64) :: sha256 = ''         !! SHA-256 of the file's bytes (as read)
   end type record_info

   interface
      function c_strtod(str, endptr) bind(c, name='strtod') result(x)
         import :: c_char, c_double, c_ptr
         character(kind=c_char), intent(in) :: str(*)
         type(c_ptr), value :: endptr
         real(c_double) :: x
      end function c_strtod
   end interface

contains

   !> Read a record file and return the table acceleration at k*dt, k = 0, 1, ... [m/s2].
   subroutine read_record(path, format, is_displacement, units, scale, dt_record, acc, info, error)
      character(len=*), intent(in) :: path            !! record file
      character(len=*), intent(in) :: format          !! 'auto', 'at2', 'values', 'time_value'
      logical, intent(in) :: is_displacement          !! the record holds displacements
      character(len=*), intent(in) :: units           !! units of the values; '' = the default
      real(dp), intent(in) :: scale                   !! factor applied to every value
      real(dp), intent(in) :: dt_record               !! sampling step [s]; <= 0: not given (AT2 only)
      real(dp), allocatable, intent(out) :: acc(:)    !! table acceleration samples [m/s2]
      type(record_info), intent(out) :: info          !! what was read
      type(error_type), allocatable, intent(out) :: error !! bad file, line or value
      character(len=:), allocatable :: text, used_units
      real(dp), allocatable :: val(:)
      real(dp) :: factor
      character(len=16) :: fmt_used
      logical :: ok
      integer :: n

      info%path = path
      info%scale = scale
      call read_file_text(path, text, error)
      if (allocated(error)) return
      call sha256_text(text, info%sha256)
      ! a UTF-8 byte order mark (some Windows editors write one) is no text of the record
      if (len(text) >= 3) then
         if (text(1:3) == achar(239)//achar(187)//achar(191)) text = text(4:)
      end if
      fmt_used = lower(format)
      info%detected = fmt_used == 'auto'
      if (fmt_used == 'auto') call detect_format(path, text, fmt_used)
      info%format = fmt_used
      used_units = trim(lower(units))
      select case (trim(fmt_used))
      case ('at2')
         call read_at2(path, text, is_displacement, used_units, dt_record, val, info, error)
      case ('values', 'time_value')
         if (.not. dt_record > 0.0_dp) then
            call fatal_error(error, "record file '"//path//"' ("//trim(fmt_used)//" format) has no DT: "// &
                             "dt_record must be given")
            return
         end if
         call read_plain(path, text, fmt_used == 'time_value', dt_record, val, error)
         info%dt = dt_record
         if (len(used_units) == 0) used_units = merge('m   ', 'm/s2', is_displacement)
      case default
         call fatal_error(error, "record_format = '"//trim(format)//"' is not one of "//record_formats)
      end select
      if (allocated(error)) return
      call units_factor(used_units, is_displacement, factor, ok)
      if (.not. ok) then
         call fatal_error(error, "record file '"//path//"': record_units = '"//used_units//"' is invalid for a "// &
                          merge('displacement', 'acceleration', is_displacement)//" record: must be one of "// &
                          record_units_list)
         return
      end if
      info%units = used_units
      n = size(val)
      info%npts = n
      if (n < 2 .or. (is_displacement .and. n < 4)) then
         call fatal_error(error, "record file '"//path//"' has "//trim(fmt_int(n))// &
                          " samples; at least "//trim(fmt_int(merge(4, 2, is_displacement)))//" are needed")
         return
      end if
      val = (factor*scale)*val
      if (is_displacement) then
         allocate (acc(n))
         acc(2:n - 1) = (val(3:n) - 2.0_dp*val(2:n - 1) + val(1:n - 2))/info%dt**2
         acc(1) = (2.0_dp*val(1) - 5.0_dp*val(2) + 4.0_dp*val(3) - val(4))/info%dt**2
         acc(n) = (2.0_dp*val(n) - 5.0_dp*val(n - 1) + 4.0_dp*val(n - 2) - val(n - 3))/info%dt**2
      else
         call move_alloc(val, acc)
      end if
      info%peak_acc = maxval(abs(acc))
   end subroutine read_record

   !> Factor from the given units to SI (m/s2 or m); ok = .false. for unknown units or
   !> units of the other kind.
   pure subroutine units_factor(units, is_displacement, factor, ok)
      character(len=*), intent(in) :: units      !! lower-case units
      logical, intent(in) :: is_displacement     !! displacement (else acceleration) units
      real(dp), intent(out) :: factor            !! multiply a value to get SI
      logical, intent(out) :: ok                 !! the units are known for this kind
      integer :: k

      ok = .false.
      factor = 1.0_dp
      do k = 1, size(unit_table)
         if (unit_table(k)%name /= units .or. (unit_table(k)%displacement .neqv. is_displacement)) cycle
         factor = unit_table(k)%factor
         ok = .true.
      end do
   end subroutine units_factor

   !> 'auto': an AT2 file has NPTS and DT on its fourth line (or the extension .at2, .dt2);
   !> otherwise the number of columns of the first data line: 1 'values', 2 'time_value'.
   subroutine detect_format(path, text, format)
      character(len=*), intent(in) :: path, text
      character(len=*), intent(out) :: format
      integer :: lo, hi, next, line, dot, ncol
      character(len=:), allocatable :: ext
      logical :: has_tab

      dot = index(path, '.', back=.true.)
      ext = ''
      if (dot > index(path, '/', back=.true.)) ext = lower(path(dot + 1:))
      if (ext == 'at2' .or. ext == 'dt2') then
         format = 'at2'
         return
      end if
      next = 1
      line = 0
      format = 'values'
      do while (next <= len(text))
         call next_line(text, next, lo, hi)
         line = line + 1
         ! a plain file's comments ('#', '!') are no PEER header, even when they name NPTS and DT
         if (is_comment(text(lo:hi))) exit
         if (line == 4) then
            if (index(upper(text(lo:hi)), 'NPTS') > 0 .and. index(upper(text(lo:hi)), 'DT') > 0) then
               format = 'at2'
               return
            end if
         end if
         if (line >= 4) exit
      end do
      ! plain: the first line with a value that is not a comment
      next = 1
      do while (next <= len(text))
         call next_line(text, next, lo, hi)
         if (is_blank(text(lo:hi), has_tab)) cycle
         if (is_comment(text(lo:hi))) cycle
         ncol = count_fields(text(lo:hi))
         if (ncol == 2) format = 'time_value'
         exit
      end do
   end subroutine detect_format

   !> PEER NGA format: line 1 the database, line 2 event and station, line 3 the kind and
   !> units ("ACCELERATION TIME SERIES IN UNITS OF G"), line 4 NPTS and DT in either
   !> spelling ("NPTS=  5590, DT=   .0050 SEC" or "5590   0.0050   NPTS, DT"), then the
   !> values, several a line.
   subroutine read_at2(path, text, is_displacement, units, dt_record, val, info, error)
      character(len=*), intent(in) :: path, text
      logical, intent(in) :: is_displacement
      character(len=:), allocatable, intent(inout) :: units
      real(dp), intent(in) :: dt_record
      real(dp), allocatable, intent(out) :: val(:)
      type(record_info), intent(inout) :: info
      type(error_type), allocatable, intent(out) :: error
      integer :: next, lo, hi, line, npts, n, stat, bad_lo, bad_hi, k, width, first
      integer :: hlo(4), hhi(4)
      real(dp) :: dt, f_declared, f_given
      character(len=:), allocatable :: h3, declared, where
      logical :: found, ok, ok_declared

      next = 1
      do line = 1, 4
         if (next > len(text)) then
            call fatal_error(error, "record file '"//path//"' (AT2 format) ends at line "//trim(fmt_int(line - 1))// &
                             ": expected four header lines, NPTS and DT on the fourth")
            return
         end if
         call next_line(text, next, hlo(line), hhi(line))
      end do
      info%title = trim(adjustl(text(hlo(1):hhi(1))))//' | '//trim(adjustl(text(hlo(2):hhi(2))))
      do k = 1, len(info%title)   ! printable ASCII only: the title goes into the JSON summary
         if (iachar(info%title(k:k)) < 32 .or. iachar(info%title(k:k)) > 126) info%title(k:k) = '?'
      end do
      ! line 3: kind and units
      h3 = upper(text(hlo(3):hhi(3)))
      where = "record file '"//path//"', line 3"
      if (index(h3, 'VELOCITY') > 0) then
         call fatal_error(error, where//": the header declares a velocity time series ('"//trim(text(hlo(3):hhi(3)))// &
                          "'); expected an acceleration or displacement record")
         return
      end if
      if (index(h3, 'DISPLACEMENT') > 0 .and. .not. is_displacement) then
         call fatal_error(error, where//": the header declares a displacement time series; set record_kind = "// &
                          "'displacement' or give an acceleration record")
         return
      end if
      if (index(h3, 'ACCELERATION') > 0 .and. is_displacement) then
         call fatal_error(error, where//": the header declares an acceleration time series, but record_kind = "// &
                          "'displacement'")
         return
      end if
      call header_units(h3, declared)
      if (len(declared) > 0) then
         ! units the header declares must be known (record_units given or not: a record_units
         ! that contradicted a unit not known here would go unnoticed)
         call units_factor(declared, is_displacement, f_declared, ok_declared)
         if (.not. ok_declared) then
            call fatal_error(error, where//": the header declares units of '"//trim(fmt_text(declared))//"' ('"// &
                             trim(fmt_text(text(hlo(3):hhi(3))))//"'), which are not units of a"// &
                             trim(merge(' displacement ', 'n acceleration', is_displacement))// &
                             " record known here ("//record_units_list//"): convert the record")
            return
         end if
         ! record_units given: it must say what the header says ('gal' is 'cm/s2')
         if (len(units) > 0) then
            call units_factor(units, is_displacement, f_given, ok)
            if (.not. ok .or. f_given /= f_declared) then
               call fatal_error(error, where//": the header declares units of '"//trim(fmt_text(declared))// &
                                "' but record_units = '"// &
                                units//"'")
               return
            end if
         end if
      end if
      if (len(units) == 0) then
         units = declared
         if (len(units) == 0) units = merge('cm', 'g ', is_displacement)
      end if
      ! line 4: NPTS and DT
      call npts_dt(path, text(hlo(4):hhi(4)), npts, dt, error)
      if (allocated(error)) return
      if (dt_record > 0.0_dp) then
         if (abs(dt_record - dt) > 1.0e-6_dp*dt) then
            call fatal_error(error, "record file '"//path//"', line 4: DT = "//trim(fmt_real(dt))// &
                             " s differs from dt_record = "//trim(fmt_real(dt_record))// &
                             " s (leave dt_record out to take the file's DT)")
            return
         end if
      end if
      info%dt = dt
      ! values
      allocate (val(npts), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "record file '"//path//"', line 4: NPTS = "//trim(fmt_int(npts))// &
                          ": not enough memory for that many values", stat_no_memory)
         return
      end if
      n = 0
      line = 4
      width = -1   ! the fixed-width fields of the body, from its first line (0: none)
      do
         call filled_line(path, text, 'numbers', next, line, lo, hi, found, error)
         if (allocated(error)) return
         if (.not. found) exit
         call line_values(text(lo:hi), val, n, stat, bad_lo, bad_hi)
         if (stat /= num_ok) then
            call value_error(path, line, text(lo:hi), stat, bad_lo, bad_hi, npts, error)
            return
         end if
         if (width < 0) then
            width = field_width(text(lo:hi))
            first = line
         end if
         if (width > 0) then
            ! a value that does not fill its field: cut short (a truncated file), shifted or glued
            call misplaced_field(text(lo:hi), width, bad_lo, bad_hi)
            if (scan(text(lo:hi), achar(9)//',') > 0) then
               call fatal_error(error, "record file '"//path//"', line "//trim(fmt_int(line))// &
                                ": a tab or a comma between values, but the values of line "//trim(fmt_int(first))// &
                                " are in fixed-width fields of "//trim(fmt_int(width))//" characters (blank-padded)")
               return
            else if (bad_lo > 0) then
               call fatal_error(error, "record file '"//path//"', line "//trim(fmt_int(line))//": value '"// &
                                text(lo + bad_lo - 1:lo + bad_hi - 1)//"' ends at column "//trim(fmt_int(bad_hi))// &
                                ", not at the end of a field: the values of line "//trim(fmt_int(first))// &
                                " are in fixed-width fields of "//trim(fmt_int(width))// &
                                " characters (a number cut short, or out of its field)")
               return
            end if
         end if
      end do
      if (n < npts) then
         call fatal_error(error, "record file '"//path//"' has "//trim(fmt_int(n))// &
                          " values after the header, but line 4 declares NPTS = "//trim(fmt_int(npts)))
         return
      end if
   end subroutine read_at2

   !> Units declared on AT2 line 3, lower case: the word after UNITS ("... IN UNITS OF G",
   !> "UNITS: CM/S/S", "UNITS (G)"), else a unit written on the line on its own or in
   !> parentheses ("ACCELERATION (CM/S2)"); '' when the line names none (PEER's files then
   !> hold g). A word after UNITS that is no unit known here is returned as it is (lower
   !> case): the caller refuses it rather than take g.
   pure subroutine header_units(h3, units)
      character(len=*), intent(in) :: h3
      character(len=:), allocatable, intent(out) :: units
      character(len=*), parameter :: separators = ' ,:;=()[]'//achar(9)//achar(13)
      character(len=:), allocatable :: w
      integer :: k, e, pos
      logical :: after_units

      units = ''
      after_units = .false.
      pos = 1
      do
         k = verify(h3(pos:), separators)
         if (k == 0) exit
         k = pos + k - 1
         e = scan(h3(k:), separators)
         if (e == 0) then
            e = len(h3)
         else
            e = k + e - 2
         end if
         w = h3(k:e)
         pos = e + 1
         do while (len(w) > 1 .and. w(len(w):len(w)) == '.')   ! 'G.' at a sentence's end
            w = w(1:len(w) - 1)
         end do
         if (w == 'UNITS' .or. w == 'UNIT') then
            after_units = .true.
            cycle
         end if
         if (after_units .and. (w == 'OF' .or. w == 'IN' .or. w == 'ARE' .or. w == 'IS')) cycle
         units = trim(known_unit(w))
         if (after_units) then
            if (len(units) == 0) units = lower(w)
            return
         end if
         ! without UNITS: only spellings that are no ordinary word ('G' and 'M' are left alone)
         if (len(units) > 0 .and. w /= 'G' .and. w /= 'M') return
         units = ''
      end do
   contains
      !> (fixed-length text, trimmed where used: README's rule on character results)
      pure function known_unit(w) result(u)
         character(len=*), intent(in) :: w
         character(len=8) :: u
         select case (w)
         case ('G')
            u = 'g'
         case ('CM/S/S', 'CM/SEC/SEC', 'CM/S2', 'CM/SEC2', 'CM/S^2', 'CM/SEC^2', 'CM/S**2', 'CM/SEC**2', 'GAL', &
               'CM/S/SEC', 'CMS2')
            u = 'cm/s2'
         case ('M/S/S', 'M/SEC/SEC', 'M/S2', 'M/SEC2', 'M/S^2', 'M/SEC^2', 'M/S**2', 'M/SEC**2')
            u = 'm/s2'
         case ('MM/S/S', 'MM/SEC/SEC', 'MM/S2', 'MM/SEC2', 'MM/S^2', 'MM/SEC^2', 'MM/S**2', 'MM/SEC**2')
            u = 'mm/s2'
         case ('CM')
            u = 'cm'
         case ('M')
            u = 'm'
         case ('MM')
            u = 'mm'
         case default
            u = ''
         end select
      end function known_unit
   end subroutine header_units

   !> NPTS and DT of AT2 line 4, in the spellings of the PEER files:
   !> "NPTS=  5590, DT=   .0050 SEC", "5590   0.0050   NPTS, DT", "NPTS, DT: 5590 0.0050 SEC".
   !> Tabs are blanks; NPTS and DT are named once each; the line holds nothing else (their
   !> values, the unit SEC after DT): a value after them is refused, not ignored.
   subroutine npts_dt(path, line, npts, dt, error)
      character(len=*), intent(in) :: path, line
      integer, intent(out) :: npts
      real(dp), intent(out) :: dt
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: up, where, expect, tok(:)
      character(len=64) :: num(2)
      integer :: k

      npts = 0; dt = 0.0_dp
      up = upper(line)
      do k = 1, len(up)   ! a tab separates words as a blank does
         if (up(k:k) == achar(9)) up(k:k) = ' '
      end do
      where = "record file '"//path//"', line 4"
      expect = "expected NPTS and DT, e.g. 'NPTS=  5590, DT=   .0050 SEC' or '5590   .0050   NPTS, DT'"
      call words(up, tok)
      call check_npts_dt_named(where, expect, line, up, tok, error)
      if (allocated(error)) return
      if (index(up, '=') > 0) then
         call keyed_npts_dt(where, line, up, tok, num, error)
      else
         call bare_npts_dt(where, line, tok, num, error)
      end if
      if (allocated(error)) return
      call npts_dt_values(where, expect, line, num, npts, dt, error)
   end subroutine npts_dt

   !> Line 4 (upper case `up`, its words `tok`) names NPTS and DT, each once.
   subroutine check_npts_dt_named(where, expect, line, up, tok, error)
      character(len=*), intent(in) :: where, expect   !! the place, the forms expected
      character(len=*), intent(in) :: line, up        !! line 4, in upper case
      character(len=*), intent(in) :: tok(:)          !! its words
      type(error_type), allocatable, intent(out) :: error
      integer :: k
      if (index(up, 'NPTS') == 0) then
         call fatal_error(error, where//": NPTS is missing; "//expect//", found '"//trim(fmt_text(line))//"'")
         return
      end if
      if (index(up, 'DT') == 0) then
         call fatal_error(error, where//": DT is missing; "//expect//", found '"//trim(fmt_text(line))//"'")
         return
      end if
      do k = 1, 2
         if (count(tok == merge('NPTS', 'DT  ', k == 1)) > 1) then
            call fatal_error(error, where//": "//trim(merge('NPTS', 'DT  ', k == 1))//" is given twice ('"// &
                             trim(fmt_text(line))//"'); line 4 gives NPTS and DT once each")
            return
         end if
      end do
   end subroutine check_npts_dt_named

   !> The texts of NPTS's and DT's values in the keyed form ('NPTS= 5590, DT= .0050 SEC'),
   !> '' for one not found; DT in another unit than seconds, or a word that is neither a key,
   !> a value nor the unit, is an error.
   subroutine keyed_npts_dt(where, line, up, tok, num, error)
      character(len=*), intent(in) :: where, line, up  !! the place, line 4, in upper case
      character(len=*), intent(in) :: tok(:)           !! its words
      character(len=*), intent(out) :: num(2)          !! NPTS's and DT's values
      type(error_type), allocatable, intent(out) :: error
      character(len=64) :: unit
      logical :: used(2)
      integer :: k
      num = ''
      call keyed_value(up, 'NPTS', num(1))
      call keyed_value(up, 'DT', num(2), unit)
      ! DT is read in seconds: another unit after it ('DT= 5 MSEC') is refused
      select case (trim(unit))
      case ('', 'SEC', 'SECS', 'S', 'SECOND', 'SECONDS')
      case default
         if (unit(1:4) /= 'NPTS') then
            call fatal_error(error, where//": DT is followed by '"//trim(fmt_text(unit))//"'; DT is read in seconds "// &
                             "(SEC), give it so ('"//trim(fmt_text(line))//"')")
            return
         end if
      end select
      ! nothing but NPTS, DT, their values and DT's unit (a missing value is told later)
      used = num == ''
      do k = 1, merge(size(tok), 0, all(num /= ''))
         select case (trim(tok(k)))
         case ('NPTS', 'DT', 'SEC', 'SECS', 'S', 'SECOND', 'SECONDS')
            cycle
         end select
         if (.not. used(1) .and. tok(k) == num(1)) then
            used(1) = .true.
         else if (.not. used(2) .and. tok(k) == num(2)) then
            used(2) = .true.
         else
            call extra_word_error(where, line, tok(k), error)
            return
         end if
      end do
   end subroutine keyed_npts_dt

   !> The texts of NPTS's and DT's values in the form without '=' ('5590   .0050   NPTS, DT'):
   !> the first two words that are not NPTS, DT or SEC, '' for one missing; a third is an error.
   subroutine bare_npts_dt(where, line, tok, num, error)
      character(len=*), intent(in) :: where, line      !! the place, line 4
      character(len=*), intent(in) :: tok(:)           !! its words, in upper case
      character(len=*), intent(out) :: num(2)          !! NPTS's and DT's values
      type(error_type), allocatable, intent(out) :: error
      integer :: k, nnum
      num = ''
      nnum = 0
      do k = 1, size(tok)
         select case (trim(tok(k)))
         case ('NPTS', 'DT', 'SEC', 'SECS', 'S')
            cycle
         end select
         nnum = nnum + 1
         if (nnum <= 2) then
            num(nnum) = tok(k)
         else
            call extra_word_error(where, line, tok(k), error)
            return
         end if
      end do
   end subroutine bare_npts_dt

   !> NPTS and DT from their values' texts: NPTS a whole number >= 1, DT a finite number > 0.
   subroutine npts_dt_values(where, expect, line, num, npts, dt, error)
      character(len=*), intent(in) :: where, expect, line  !! the place, the forms expected, line 4
      character(len=*), intent(in) :: num(2)               !! NPTS's and DT's values ('' missing)
      integer, intent(out) :: npts
      real(dp), intent(out) :: dt
      type(error_type), allocatable, intent(out) :: error
      integer :: stat, ios
      npts = 0; dt = 0.0_dp
      if (num(1) == '') then
         call fatal_error(error, where//": cannot find the value of NPTS; "//expect//", found '"//trim(fmt_text(line))//"'")
         return
      end if
      if (num(2) == '') then
         call fatal_error(error, where//": DT has no value; "//expect//", found '"//trim(fmt_text(line))//"'")
         return
      end if
      if (verify(trim(num(1)), '0123456789') /= 0) then
         call fatal_error(error, where//": NPTS = '"//trim(num(1))//"' is not a whole number")
         return
      end if
      read (num(1), '(i64)', iostat=ios) npts
      if (ios /= 0 .or. npts < 1) then
         call fatal_error(error, where//": NPTS = '"//trim(num(1))//"' must be a whole number >= 1")
         return
      end if
      call parse_real(trim(num(2)), dt, stat)
      if (stat /= num_ok) then
         call fatal_error(error, where//": DT = '"//trim(num(2))//"' is not a finite number")
         return
      end if
      if (dt <= 0.0_dp) then
         call fatal_error(error, where//": DT = "//trim(num(2))//" s must be > 0")
      end if
   end subroutine npts_dt_values

   !> The error of a word line 4 does not hold (a value after the header, a stray word).
   subroutine extra_word_error(where, line, w, error)
      character(len=*), intent(in) :: where, line, w   !! the place, line 4, the word
      type(error_type), allocatable, intent(out) :: error
      call fatal_error(error, where//": '"//trim(fmt_text(w))//"' after NPTS and DT ('"//trim(fmt_text(line))// &
                       "'); line 4 holds NPTS, DT and their values only, the values start on line 5")
   end subroutine extra_word_error

   !> The word after "KEY=" (KEY as a whole word) in upper-case text s, '' when absent;
   !> after: the word that follows it.
   pure subroutine keyed_value(s, key, v, after)
      character(len=*), intent(in) :: s, key
      character(len=*), intent(out) :: v
      character(len=*), intent(out), optional :: after
      character(len=len(s)) :: rest
      integer :: p, q, e, e2
      v = ''
      if (present(after)) after = ''
      p = 0
      do
         q = index(s(p + 1:), key)
         if (q == 0) return
         p = p + q
         if (p > 1) then
            if (index('ABCDEFGHIJKLMNOPQRSTUVWXYZ', s(p - 1:p - 1)) > 0) cycle
         end if
         e = verify(s(p + len(key):), ' ')
         if (e == 0) return
         e = p + len(key) - 1 + e
         if (s(e:e) /= '=') cycle
         rest = adjustl(s(e + 1:))
         e = scan(rest, ' ,;'//achar(9)//achar(13))
         v = rest
         if (e > 0) v = rest(1:e - 1)
         if (v == 'SEC' .or. v == 'NPTS' .or. v == 'DT') then
            v = ''
            return
         end if
         if (present(after) .and. e > 0) then
            rest = adjustl(rest(e + 1:))
            e2 = scan(rest, ' ,;'//achar(9)//achar(13))
            if (e2 > 0) rest = rest(1:e2 - 1)
            after = rest
         end if
         return
      end do
   end subroutine keyed_value

   !> One value a line ('values') or time and value ('time_value'); blank lines and lines
   !> starting with '#' or '!' are skipped.
   subroutine read_plain(path, text, two, dt_record, val, error)
      character(len=*), intent(in) :: path, text
      logical, intent(in) :: two
      real(dp), intent(in) :: dt_record
      real(dp), allocatable, intent(out) :: val(:)
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: buf(:)
      real(dp) :: pair(2), t1
      integer :: next, lo, hi, line, n, nl, k, stat, bad_lo, bad_hi, ncol, m
      logical :: found
      character(len=:), allocatable :: where, expected

      ncol = merge(2, 1, two)
      expected = trim(columns_text(ncol))   ! once: only a message uses it
      nl = 1
      do k = 1, len(text)
         if (text(k:k) == achar(10)) nl = nl + 1
      end do
      allocate (buf(nl))
      n = 0
      line = 0
      next = 1
      t1 = 0.0_dp
      do
         call filled_line(path, text, expected, next, line, lo, hi, found, error)
         if (allocated(error)) return
         if (.not. found) exit
         if (is_comment(text(lo:hi))) cycle
         m = 0
         call line_values(text(lo:hi), pair, m, stat, bad_lo, bad_hi)
         if (stat == 4 .or. (stat == num_ok .and. m /= ncol)) then
            call fatal_error(error, "record file '"//path//"', line "//trim(fmt_int(line))//": expected "// &
                             expected//", found "//trim(fmt_int(count_fields(text(lo:hi))))//" values")
            return
         end if
         if (stat /= num_ok) then
            call value_error(path, line, text(lo:hi), stat, bad_lo, bad_hi, 0, error)
            return
         end if
         n = n + 1
         buf(n) = pair(ncol)
         if (two) then
            if (n == 1) t1 = pair(1)
            if (abs(pair(1) - t1 - (n - 1)*dt_record) > 1.0e-6_dp*dt_record + 1.0e-9_dp*abs(pair(1))) then
               where = "record file '"//path//"', line "//trim(fmt_int(line))
               call fatal_error(error, where//": time "//trim(adjustl(text(lo + bad_lo - 1:lo + bad_hi - 1)))// &
                                " is not on the grid of dt_record = "//trim(fmt_real(dt_record))// &
                                " s starting at "//trim(fmt_real(t1))//" s (expected "// &
                                trim(fmt_real(t1 + (n - 1)*dt_record))//" s)")
               return
            end if
         end if
      end do
      val = buf(1:n)
   end subroutine read_plain

   pure function columns_text(ncol) result(s)
      integer, intent(in) :: ncol
      character(len=40) :: s
      if (ncol == 1) then
         s = 'one column (one value a line)'
      else
         s = 'two columns (time and value)'
      end if
   end function columns_text

   !> Parse the values of one line into v(n+1:); stat 0 or the num_* code of the first bad
   !> token (bad_lo:bad_hi its position in the line), 4 when v is full, 5 for an empty field
   !> between commas. On success bad_lo:bad_hi is the first token.
   subroutine line_values(s, v, n, stat, bad_lo, bad_hi)
      character(len=*), intent(in) :: s
      real(dp), intent(inout) :: v(:)
      integer, intent(inout) :: n
      integer, intent(out) :: stat, bad_lo, bad_hi
      integer :: i, j, ls
      logical :: comma, any_field
      real(dp) :: x

      stat = num_ok
      bad_lo = 1; bad_hi = 0
      ls = len(s)
      i = 1
      comma = .false.
      any_field = .false.
      do
         do while (i <= ls)
            if (.not. is_space(s(i:i))) exit
            i = i + 1
         end do
         if (i > ls) exit
         if (s(i:i) == ',') then
            if (comma .or. .not. any_field) then
               stat = 5; bad_lo = i; bad_hi = i
               return
            end if
            comma = .true.
            i = i + 1
            cycle
         end if
         j = i
         do while (j <= ls)
            if (is_space(s(j:j)) .or. s(j:j) == ',') exit
            j = j + 1
         end do
         if (.not. any_field) then
            bad_lo = i; bad_hi = j - 1
         end if
         call parse_real(s(i:j - 1), x, stat)
         if (stat /= num_ok) then
            bad_lo = i; bad_hi = j - 1
            return
         end if
         if (n >= size(v)) then
            stat = 4; bad_lo = i; bad_hi = j - 1
            return
         end if
         n = n + 1
         v(n) = x
         any_field = .true.
         comma = .false.
         i = j
      end do
      if (comma) then
         stat = 5; bad_lo = ls; bad_hi = ls
      end if
   end subroutine line_values

   subroutine value_error(path, line, s, stat, lo, hi, npts, error)
      character(len=*), intent(in) :: path, s
      integer, intent(in) :: line, stat, lo, hi, npts
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: where, tok
      where = "record file '"//path//"', line "//trim(fmt_int(line))
      tok = trim(fmt_text(s(lo:hi)))
      select case (stat)
      case (num_nan)
         call fatal_error(error, where//": '"//tok//"' is NaN: not finite; expected a finite number")
      case (num_infinite)
         call fatal_error(error, where//": value '"//tok//"' is not finite")
      case (4)
         call fatal_error(error, where//": value '"//tok//"' is beyond the NPTS = "//trim(fmt_int(npts))// &
                          " values that line 4 declares")
      case (5)
         call fatal_error(error, where//": empty field (a comma with no value before or after it); "// &
                          "expected a number")
      case default
         if (scan(tok, '*/') > 0) then
            call fatal_error(error, where//": '"//tok//"' is not a number (Fortran list-directed repeat "// &
                             "counts 'r*', '*' and '/' are not accepted in records)")
         else
            call fatal_error(error, where//": '"//tok//"' is not a number")
         end if
      end select
   end subroutine value_error

   !> A decimal number: [sign] digits [. digits] [e|E|d|D [sign] digits], at least one
   !> digit in the mantissa. stat: 0, 1 not a number, 2 NaN, 3 infinite (or overflow).
   subroutine parse_real(tok, x, stat)
      character(len=*), intent(in) :: tok   !! the token, without blanks
      real(dp), intent(out) :: x            !! its value
      integer, intent(out) :: stat          !! 0 ok, 1 syntax, 2 NaN, 3 not finite
      character(kind=c_char, len=80) :: buf
      integer :: i, n, nd
      character :: c
      character(len=:), allocatable :: low

      x = 0.0_dp
      stat = num_syntax
      n = len(tok)
      if (n == 0 .or. n >= len(buf)) return
      i = 1
      if (tok(1:1) == '+' .or. tok(1:1) == '-') i = 2
      nd = 0
      do while (i <= n)
         c = tok(i:i)
         if (c < '0' .or. c > '9') exit
         nd = nd + 1; i = i + 1
      end do
      if (i <= n) then
         if (tok(i:i) == '.') then
            i = i + 1
            do while (i <= n)
               c = tok(i:i)
               if (c < '0' .or. c > '9') exit
               nd = nd + 1; i = i + 1
            end do
         end if
      end if
      if (nd == 0) then
         low = lower(tok)
         if (low(merge(2, 1, scan(low(1:1), '+-') > 0):) == 'nan' .or. index(low, 'nan(') > 0) then
            stat = num_nan
         else if (any(low == ['inf      ', '+inf     ', '-inf     ', 'infinity ', '+infinity', '-infinity'])) then
            stat = num_infinite
         end if
         return
      end if
      buf(1:i - 1) = tok(1:i - 1)
      if (i <= n) then
         if (index('eEdD', tok(i:i)) == 0) return
         buf(i:i) = 'e'
         i = i + 1
         if (i <= n) then
            if (tok(i:i) == '+' .or. tok(i:i) == '-') then
               buf(i:i) = tok(i:i)
               i = i + 1
            end if
         end if
         nd = 0
         do while (i <= n)
            c = tok(i:i)
            if (c < '0' .or. c > '9') exit
            buf(i:i) = c
            nd = nd + 1; i = i + 1
         end do
         if (nd == 0 .or. i <= n) return
      end if
      buf(n + 1:n + 1) = c_null_char
      x = c_strtod(buf, c_null_ptr)
      if (ieee_is_nan(x)) then
         stat = num_nan
      else if (.not. ieee_is_finite(x)) then
         stat = num_infinite
      else
         stat = num_ok
      end if
   end subroutine parse_real

   !> The width of the fixed-width fields of a record line (an AT2 body line as PEER writes
   !> them, FORTRAN's 5E15.7 and the like): w when the line holds at least two values of which
   !> the j-th ends at column j w (w: where the first ends), every field blank-padded on the
   !> left (the first value too: a line that starts with a value sets no fields), all of
   !> them but perhaps the last (a line cut inside its last value still shows its fields:
   !> misplaced_field finds that value); 0 when it does not (values separated freely, a tab
   !> or a comma among them).
   pure integer function field_width(s) result(w)
      character(len=*), intent(in) :: s   !! the line
      integer :: i, j, k

      w = 0
      if (len(s) == 0 .or. scan(s, achar(9)//',') > 0) return
      if (s(1:1) /= ' ') return
      k = 0
      i = 1
      do
         call next_field(s, i, j)
         if (i > len(s)) exit
         k = k + 1
         if (k == 1) then
            w = j
         else if (j /= k*w) then
            ! misplaced: only the last value may be, after two in their fields
            if (k < 3 .or. verify(s(j + 1:), ' '//achar(13)) /= 0) w = 0
            return
         end if
         i = j + 1
      end do
      if (k < 2) w = 0
   end function field_width

   !> The first value of a line that does not end at the end of a field of `width` columns
   !> (or starts in the field before its own): its columns lo:hi; lo = 0 when every value
   !> fills its field as field_width found them (a shorter last line included).
   pure subroutine misplaced_field(s, width, lo, hi)
      character(len=*), intent(in) :: s     !! the line
      integer, intent(in) :: width          !! the fields' width (> 0)
      integer, intent(out) :: lo, hi        !! the misplaced value, or 0, 0
      integer :: i, j

      lo = 0
      hi = 0
      i = 1
      do
         call next_field(s, i, j)
         if (i > len(s)) return
         if (mod(j, width) /= 0 .or. i <= j - width) then
            lo = i
            hi = j
            return
         end if
         i = j + 1
      end do
   end subroutine misplaced_field

   !> The next value of a line from column i on: its columns i:j (blanks and carriage
   !> returns skipped); i > len(s) when there is none.
   pure subroutine next_field(s, i, j)
      character(len=*), intent(in) :: s     !! the line
      integer, intent(inout) :: i           !! where to look from; the value's first column
      integer, intent(out) :: j             !! its last column
      do while (i <= len(s))
         if (s(i:i) /= ' ' .and. s(i:i) /= achar(13)) exit
         i = i + 1
      end do
      j = i
      do while (j < len(s))
         if (s(j + 1:j + 1) == ' ' .or. s(j + 1:j + 1) == achar(13)) exit
         j = j + 1
      end do
   end subroutine next_field

   ! ------------------------------------------------------------------ text helpers
   !> The next line from next that holds more than blanks: text(lo:hi), line its number
   !> (counted on from the last); a line of blanks is skipped, one of blanks and a tab or a
   !> comma is an error (no value where `expected` were). found = .false. at the text's end or
   !> on the error.
   subroutine filled_line(path, text, expected, next, line, lo, hi, found, error)
      character(len=*), intent(in) :: path                !! the record file (for the message)
      character(len=*), intent(in) :: text                !! its text
      character(len=*), intent(in) :: expected            !! what a line holds, for the message
      integer, intent(inout) :: next                      !! where the next line starts
      integer, intent(inout) :: line                      !! the number of the line
      integer, intent(out) :: lo, hi                      !! the line found
      logical, intent(out) :: found                       !! a line was found
      type(error_type), allocatable, intent(out) :: error   !! a line without a value
      logical :: has_tab

      found = .false.
      lo = 1
      hi = 0
      do while (next <= len(text))
         call next_line(text, next, lo, hi)
         line = line + 1
         if (.not. is_blank(text(lo:hi), has_tab)) then
            found = .true.
            return
         end if
         if (has_tab) then
            call fatal_error(error, "record file '"//path//"', line "//trim(fmt_int(line))// &
                             ": no value (only blanks, tabs or commas); expected "//expected)
            return
         end if
      end do
   end subroutine filled_line

   !> The line starting at next: text(lo:hi), without its newline or carriage return;
   !> next moves past the newline.
   pure subroutine next_line(text, next, lo, hi)
      character(len=*), intent(in) :: text
      integer, intent(inout) :: next
      integer, intent(out) :: lo, hi
      integer :: k
      lo = next
      k = index(text(next:), achar(10))
      if (k == 0) then
         hi = len(text)
         next = len(text) + 1
      else
         hi = next + k - 2
         next = next + k
      end if
      if (hi >= lo) then
         if (text(hi:hi) == achar(13)) hi = hi - 1
      end if
   end subroutine next_line

   pure logical function is_space(c)
      character, intent(in) :: c
      is_space = c == ' ' .or. c == achar(9) .or. c == achar(13)
   end function is_space

   !> Only blanks, tabs and commas; has_tab tells whether a tab or a comma is among them
   !> (a line of blanks is skipped; one with a tab or comma but no value is an error).
   logical function is_blank(s, has_tab)
      character(len=*), intent(in) :: s
      logical, intent(out) :: has_tab
      is_blank = verify(s, ' '//achar(9)//achar(13)//',') == 0
      has_tab = is_blank .and. scan(s, achar(9)//',') > 0
   end function is_blank

   pure logical function is_comment(s)
      character(len=*), intent(in) :: s
      integer :: k
      k = verify(s, ' '//achar(9))
      is_comment = .false.
      if (k > 0) is_comment = s(k:k) == '#' .or. s(k:k) == '!'
   end function is_comment

   !> Number of fields of a line (blanks, tabs or commas between them).
   pure integer function count_fields(s)
      character(len=*), intent(in) :: s
      integer :: i
      logical :: in_tok
      count_fields = 0
      in_tok = .false.
      do i = 1, len(s)
         if (is_space(s(i:i)) .or. s(i:i) == ',') then
            in_tok = .false.
         else if (.not. in_tok) then
            in_tok = .true.
            count_fields = count_fields + 1
         end if
      end do
   end function count_fields

   !> Words of a line split at blanks, tabs, commas, colons and '='.
   pure subroutine words(s, w)
      character(len=*), intent(in) :: s
      character(len=:), allocatable, intent(out) :: w(:)
      integer :: i, j, n
      character(len=*), parameter :: seps = ' ,:='//achar(9)//achar(13)
      n = 0
      i = 1
      allocate (character(len=64) :: w(len(s)/2 + 1))
      do while (i <= len(s))
         if (index(seps, s(i:i)) > 0) then
            i = i + 1
            cycle
         end if
         j = i
         do while (j <= len(s))
            if (index(seps, s(j:j)) > 0) exit
            j = j + 1
         end do
         n = n + 1
         w(n) = s(i:j - 1)
         i = j
      end do
      w = w(1:n)
   end subroutine words

   pure function upper(s) result(u)
      character(len=*), intent(in) :: s
      character(len=len(s)) :: u
      integer :: i, c
      u = s
      do i = 1, len(s)
         c = iachar(s(i:i))
         if (c >= iachar('a') .and. c <= iachar('z')) u(i:i) = achar(c - 32)
      end do
   end function upper

end module fd_record
