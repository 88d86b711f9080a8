!> Text-file helpers shared by the deck and record readers: whole files as lines,
!> and small string utilities. No state; errors name the file.
module fd_textio
   use fd_error, only: error_type, fatal_error
   implicit none
   private

   public :: line_type, read_text_file, lower, split_tokens

   !> One line of text.
   type :: line_type
      character(len=:), allocatable :: s !! the line, without its newline
   end type line_type

contains

   !> Read a whole text file into lines.
   subroutine read_text_file(path, lines, error)
      character(len=*), intent(in) :: path                   !! file to read
      type(line_type), allocatable, intent(out) :: lines(:)  !! its lines
      type(error_type), allocatable, intent(out) :: error    !! set when it cannot be read
      type(line_type), allocatable :: tmp(:)
      character(len=:), allocatable :: line
      character(len=512) :: msg
      integer :: unit, ios, n
      logical :: exists

      inquire (file=path, exist=exists)
      if (.not. exists) then
         call fatal_error(error, "file '"//path//"' does not exist")
         return
      end if
      open (newunit=unit, file=path, status='old', action='read', form='formatted', &
            access='sequential', iostat=ios, iomsg=msg)
      if (ios /= 0) then
         call fatal_error(error, "cannot open file '"//path//"': "//trim(msg))
         return
      end if
      allocate (lines(64))
      n = 0
      do
         call get_line(unit, line, ios)
         if (ios /= 0) exit
         n = n + 1
         if (n > size(lines)) then
            allocate (tmp(2*size(lines)))
            tmp(1:n - 1) = lines(1:n - 1)
            call move_alloc(tmp, lines)
         end if
         lines(n)%s = line
      end do
      close (unit)
      if (.not. is_iostat_end(ios)) then
         call fatal_error(error, "cannot read file '"//path//"'")
         return
      end if
      lines = lines(1:n)
   end subroutine read_text_file

   !> Read one line of any length.
   subroutine get_line(unit, line, iostat)
      integer, intent(in) :: unit                          !! unit to read from
      character(len=:), allocatable, intent(out) :: line   !! the line read
      integer, intent(out) :: iostat                       !! 0, or the end-of-file/error status
      character(len=1024) :: buf
      integer :: nread

      line = ''
      do
         read (unit, '(a)', advance='no', iostat=iostat, size=nread) buf
         if (iostat == 0) then
            line = line//buf(1:nread)
            cycle
         end if
         if (is_iostat_eor(iostat)) then
            line = line//buf(1:nread)
            iostat = 0
         else if (is_iostat_end(iostat) .and. len(line) > 0) then
            iostat = 0
         end if
         exit
      end do
      ! tolerate files written on Windows
      if (len(line) > 0) then
         if (line(len(line):len(line)) == achar(13)) line = line(1:len(line) - 1)
      end if
   end subroutine get_line

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
