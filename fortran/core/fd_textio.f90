!> Text-file helpers shared by the deck and record readers: whole files as lines,
!> and small string utilities. No state; errors name the file.
module fd_textio
   use, intrinsic :: iso_c_binding, only: c_char, c_ptr, c_size_t, c_int, c_null_char, c_associated
   use fd_error, only: error_type, fatal_error, fmt_int
   implicit none
   private

   public :: line_type, read_text_file, read_file_text, split_lines, lower, split_tokens, max_file_bytes
   public :: cr_line_ends

   !> Largest text file read (a deck or a record): 1 GiB. Lengths stay in default integers.
   integer, parameter :: max_file_bytes = 2**30

   interface
      function c_fopen(path, mode) bind(c, name='fopen') result(fp)
         import :: c_char, c_ptr
         character(kind=c_char), intent(in) :: path(*), mode(*)
         type(c_ptr) :: fp
      end function c_fopen
      function c_fread(buf, size, count, fp) bind(c, name='fread') result(got)
         import :: c_char, c_ptr, c_size_t
         character(kind=c_char), intent(out) :: buf(*)
         integer(c_size_t), value :: size, count
         type(c_ptr), value :: fp
         integer(c_size_t) :: got
      end function c_fread
      function c_fclose(fp) bind(c, name='fclose') result(stat)
         import :: c_ptr, c_int
         type(c_ptr), value :: fp
         integer(c_int) :: stat
      end function c_fclose
      function c_ferror(fp) bind(c, name='ferror') result(stat)
         import :: c_ptr, c_int
         type(c_ptr), value :: fp
         integer(c_int) :: stat
      end function c_ferror
   end interface

   !> One line of text.
   type :: line_type
      character(len=:), allocatable :: s !! the line, without its newline
   end type line_type

contains

   !> Read a whole text file into lines. The file is read with C stdio, not a Fortran unit:
   !> gfortran refuses to connect one file to two units at once, which made runs in several
   !> threads that read the same deck or record fail.
   subroutine read_text_file(path, lines, error)
      character(len=*), intent(in) :: path                   !! file to read
      type(line_type), allocatable, intent(out) :: lines(:)  !! its lines
      type(error_type), allocatable, intent(out) :: error    !! set when it cannot be read
      character(len=:), allocatable :: text
      integer :: stat

      call read_file_text(path, text, error)
      if (allocated(error)) return
      call split_lines(text, lines, stat)
      if (stat /= 0) call fatal_error(error, "not enough memory for the lines of file '"//path//"' ("// &
                                      trim(fmt_int(len(text)))//" bytes)")
   end subroutine read_text_file

   !> Read a whole text file into one string (a buffer that doubles: linear time; growing
   !> the string chunk by chunk took quadratic time). Errors name the file and say what it
   !> is: missing, a directory, unreadable, larger than max_file_bytes, or not text (a NUL
   !> character); memory that cannot be had is an error too.
   subroutine read_file_text(path, text, error)
      character(len=*), intent(in) :: path                   !! file to read
      character(len=:), allocatable, intent(out) :: text     !! its bytes
      type(error_type), allocatable, intent(out) :: error    !! set when it cannot be read
      character(len=:), allocatable :: buf, grown
      character(len=len(path) + 64) :: msg
      type(c_ptr) :: fp
      integer(c_size_t) :: got, want
      integer :: stat, n, cap, nul
      logical :: failed

      msg = path_problem(path)
      if (len_trim(msg) > 0) then
         call fatal_error(error, trim(msg))
         return
      end if
      fp = c_fopen(path//c_null_char, 'rb'//c_null_char)
      if (.not. c_associated(fp)) then
         call fatal_error(error, "cannot open file '"//path//"'")
         return
      end if
      ! read into a buffer that doubles when full (works for pipes too): the text is
      ! copied O(log size) times, not once per chunk
      cap = 65536
      allocate (character(len=cap) :: buf, stat=stat)
      n = 0
      failed = .false.
      do while (stat == 0)
         if (n == cap) then
            if (cap >= max_file_bytes) then
               stat = c_fclose(fp)
               call fatal_error(error, "file '"//path//"' is larger than "//trim(fmt_int(max_file_bytes/2**20))// &
                                " MiB: not a deck or a record")
               return
            end if
            allocate (character(len=2*cap) :: grown, stat=stat)
            if (stat /= 0) exit
            grown(1:n) = buf(1:n)
            call move_alloc(grown, buf)
            cap = 2*cap
         end if
         want = int(cap - n, c_size_t)
         got = c_fread(buf(n + 1:cap), 1_c_size_t, want, fp)
         n = n + int(got)
         if (got < want) then
            failed = c_ferror(fp) /= 0
            exit
         end if
      end do
      if (stat == 0) allocate (character(len=n) :: text, stat=stat)
      if (stat /= 0) then
         stat = c_fclose(fp)
         call fatal_error(error, "not enough memory to read file '"//path//"' ("//trim(fmt_int(n))//" bytes read)")
         return
      end if
      stat = c_fclose(fp)
      if (failed) then
         call fatal_error(error, "cannot read file '"//path//"' (an input/output error after "// &
                          trim(fmt_int(n))//" bytes)")
         return
      end if
      text = buf(1:n)
      nul = index(text, achar(0))
      if (nul > 0) then
         call fatal_error(error, "file '"//path//"', line "//trim(fmt_int(count_lines(text(1:nul))))// &
                          ": a NUL character (byte 0): not a text file")
         return
      end if
   end subroutine read_file_text

   !> What keeps a file from being read, checked in this order: a NUL in its name, no such
   !> file, a directory, no permission to read; blank when none of them. (inquire asks the
   !> system as access(2) does: F_OK for exist, R_OK for read.)
   function path_problem(path) result(msg)
      character(len=*), intent(in) :: path   !! the file's name
      character(len=len(path) + 64) :: msg   !! the message, trimmed where used
      character(len=8) :: readable
      logical :: exists, directory

      msg = ''
      if (index(path, achar(0)) > 0) then
         msg = "the file name '"//path(1:index(path, achar(0)) - 1)//"...' contains a NUL character"
         return
      end if
      inquire (file=path, exist=exists, read=readable)
      inquire (file=path//'/.', exist=directory)
      if (.not. exists) then
         msg = "file '"//path//"' does not exist"
      else if (directory) then
         msg = "'"//path//"' is a directory, not a file"
      else if (readable == 'NO') then
         msg = "file '"//path//"' is not readable (permission denied)"
      end if
   end function path_problem

   !> Number of the line holding the last character of text (1 + newlines before it).
   pure integer function count_lines(text) result(n)
      character(len=*), intent(in) :: text
      integer :: i
      n = 1
      do i = 1, len(text) - 1
         if (text(i:i) == achar(10)) n = n + 1
      end do
   end function count_lines

   !> Split text at newlines (a final newline ends the last line; carriage returns dropped).
   pure subroutine split_lines(text, lines, stat)
      character(len=*), intent(in) :: text                   !! the text
      type(line_type), allocatable, intent(out) :: lines(:)  !! its lines (none if stat /= 0)
      integer, intent(out), optional :: stat                 !! 0, or not enough memory
      integer :: i, start, n, last, st

      n = 0
      do i = 1, len(text)
         if (text(i:i) == achar(10)) n = n + 1
      end do
      if (len(text) > 0) then
         if (text(len(text):len(text)) /= achar(10)) n = n + 1
      end if
      if (present(stat)) stat = 0
      allocate (lines(n), stat=st)
      if (st /= 0) then
         if (present(stat)) stat = st
         return
      end if
      n = 0
      start = 1
      do i = 1, len(text)
         if (text(i:i) /= achar(10) .and. i < len(text)) cycle
         n = n + 1
         last = i
         if (text(i:i) == achar(10)) last = i - 1
         if (last >= start) then
            if (text(last:last) == achar(13)) last = last - 1
         end if
         allocate (character(len=max(0, last - start + 1)) :: lines(n)%s, stat=st)
         if (st /= 0) then
            deallocate (lines)
            allocate (lines(0))
            if (present(stat)) stat = st
            return
         end if
         lines(n)%s = text(start:last)
         start = i + 1
      end do
   end subroutine split_lines

   !> Why a text's lines are not read as its author sees them: lines end with LF or CR LF,
   !> and a text whose lines end with CR alone (the classic Mac OS line end: CRs and no LF)
   !> is one long line. The reason, to follow the file's name in a message (': ...'); blank
   !> when the text has an LF or no CR.
   pure function cr_line_ends(text) result(msg)
      character(len=*), intent(in) :: text   !! the file's text
      character(len=200) :: msg

      msg = ''
      if (index(text, achar(13)) == 0 .or. index(text, achar(10)) > 0) return
      msg = ": its lines end with CR alone (the classic Mac OS line end), which ends no line here: "// &
            "save it with LF (Unix) or CR LF (Windows) line ends"
   end function cr_line_ends

   !> Lower-case copy of a string.
   pure function lower(str) result(low)
      character(len=*), intent(in) :: str  !! text
      character(len=len(str)) :: low       !! text in lower case
      integer :: i, c

      low = str
      do i = 1, len(str)
         c = iachar(str(i:i))
         if (c >= iachar('A') .and. c <= iachar('Z')) low(i:i) = achar(c + 32)
      end do
   end function lower

   !> Split a string at blanks, tabs and commas into tokens. Two passes, count then fill:
   !> growing the array by a constructor of line_type leaks the constructor's temporaries
   !> (their allocatable components) under gfortran.
   pure subroutine split_tokens(str, tokens)
      character(len=*), intent(in) :: str                    !! text to split
      type(line_type), allocatable, intent(out) :: tokens(:)  !! the tokens, in order
      integer :: i, start, n, pass
      logical :: sep

      do pass = 1, 2
         n = 0
         start = 0
         do i = 1, len(str) + 1
            if (i > len(str)) then
               sep = .true.
            else
               sep = str(i:i) == ' ' .or. str(i:i) == ',' .or. str(i:i) == achar(9)
            end if
            if (sep) then
               if (start > 0) then
                  n = n + 1
                  if (pass == 2) tokens(n)%s = str(start:i - 1)
                  start = 0
               end if
            else if (start == 0) then
               start = i
            end if
         end do
         if (pass == 1) allocate (tokens(n))
      end do
   end subroutine split_tokens

end module fd_textio
