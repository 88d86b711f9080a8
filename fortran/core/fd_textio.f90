!> Text-file helpers shared by the deck and record readers: whole files as lines,
!> and small string utilities. No state; errors name the file.
module fd_textio
   use, intrinsic :: iso_c_binding, only: c_char, c_ptr, c_size_t, c_int, c_null_char, c_associated
   use fd_error, only: error_type, fatal_error
   implicit none
   private

   public :: line_type, read_text_file, read_file_text, split_lines, lower, split_tokens

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

      call read_file_text(path, text, error)
      if (allocated(error)) return
      call split_lines(text, lines)
   end subroutine read_text_file

   !> Read a whole file into one string (a buffer that doubles: linear time; growing the
   !> string chunk by chunk took quadratic time).
   subroutine read_file_text(path, text, error)
      character(len=*), intent(in) :: path                   !! file to read
      character(len=:), allocatable, intent(out) :: text     !! its bytes
      type(error_type), allocatable, intent(out) :: error    !! set when it cannot be read
      character(len=:), allocatable :: buf, grown
      type(c_ptr) :: fp
      integer(c_size_t) :: got, want
      integer :: stat, n, cap
      logical :: exists

      inquire (file=path, exist=exists)
      if (.not. exists) then
         call fatal_error(error, "file '"//path//"' does not exist")
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
      allocate (character(len=cap) :: buf)
      n = 0
      do
         if (n == cap) then
            allocate (character(len=2*cap) :: grown)
            grown(1:n) = buf(1:n)
            call move_alloc(grown, buf)
            cap = 2*cap
         end if
         want = int(cap - n, c_size_t)
         got = c_fread(buf(n + 1:cap), 1_c_size_t, want, fp)
         n = n + int(got)
         if (got < want) exit
      end do
      text = buf(1:n)
      stat = c_fclose(fp)
   end subroutine read_file_text

   !> Split text at newlines (a final newline ends the last line; carriage returns dropped).
   pure subroutine split_lines(text, lines)
      character(len=*), intent(in) :: text                   !! the text
      type(line_type), allocatable, intent(out) :: lines(:)  !! its lines
      integer :: i, start, n

      n = 0
      do i = 1, len(text)
         if (text(i:i) == achar(10)) n = n + 1
      end do
      if (len(text) > 0) then
         if (text(len(text):len(text)) /= achar(10)) n = n + 1
      end if
      allocate (lines(n))
      n = 0
      start = 1
      do i = 1, len(text)
         if (text(i:i) /= achar(10) .and. i < len(text)) cycle
         n = n + 1
         if (text(i:i) == achar(10)) then
            lines(n)%s = text(start:i - 1)
         else
            lines(n)%s = text(start:i)
         end if
         if (len(lines(n)%s) > 0) then
            if (lines(n)%s(len(lines(n)%s):) == achar(13)) lines(n)%s = lines(n)%s(1:len(lines(n)%s) - 1)
         end if
         start = i + 1
      end do
   end subroutine split_lines

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

   !> Split a string at blanks, tabs and commas into tokens.
   pure subroutine split_tokens(str, tokens)
      character(len=*), intent(in) :: str                    !! text to split
      type(line_type), allocatable, intent(out) :: tokens(:)  !! the tokens, in order
      integer :: i, start, n
      logical :: sep

      allocate (tokens(0))
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
               tokens = [tokens, line_type(str(start:i - 1))]
               start = 0
            end if
         else if (start == 0) then
            start = i
         end if
      end do
   end subroutine split_tokens

end module fd_textio
