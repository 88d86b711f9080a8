!> Unit tests of the text-file reader (fd_textio): a file of several read buffers (the
!> buffer grows geometrically), line ends (LF, CRLF, none at the end), a missing file, a
!> directory, a file with a NUL character; lines that end with CR alone; a text as a message
!> echoes it (fmt_text).
module test_fd_textio
   use testdrive, only: new_unittest, unittest_type, error_type, check, test_failed
   use fd_error, only: fd_error_type => error_type, fmt_int, fmt_text
   use fd_textio, only: line_type, read_text_file, cr_line_ends
   implicit none
   private

   public :: collect_textio

contains

   subroutine collect_textio(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("large file, line ends", test_large_file), &
                  new_unittest("missing file", test_missing), &
                  new_unittest("a directory", test_directory), &
                  new_unittest("a NUL character", test_nul), &
                  new_unittest("an empty file", test_empty), &
                  new_unittest("lines that end with CR alone", test_lone_cr), &
                  new_unittest("an echoed text: 80 characters and its length", test_echo) &
                  ]
   end subroutine collect_textio

   !> 40000 lines (about 0.6 MB, ten 64 KiB buffers), every seventh ending in CRLF, the last
   !> without a newline: every line read back exactly.
   subroutine test_large_file(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: path = 'test_fd_textio.tmp'
      type(line_type), allocatable :: lines(:)
      type(fd_error_type), allocatable :: err
      integer :: unit, i, n
      character(len=:), allocatable :: eol

      n = 40000
      open (newunit=unit, file=path, access='stream', form='unformatted', status='replace')
      do i = 1, n
         eol = achar(10)
         if (mod(i, 7) == 0) eol = achar(13)//achar(10)
         if (i == n) eol = ''
         write (unit) 'line '//trim(fmt_int(i))//' of the test'//eol
      end do
      close (unit)
      call read_text_file(path, lines, err)
      open (newunit=unit, file=path, status='old')
      close (unit, status='delete')
      if (allocated(err)) then
         call test_failed(error, err%message); return
      end if
      call check(error, size(lines), n)
      if (allocated(error)) return
      do i = 1, n
         if (lines(i)%s /= 'line '//trim(fmt_int(i))//' of the test') then
            call test_failed(error, "line "//trim(fmt_int(i))//" read as '"//lines(i)%s//"'"); return
         end if
      end do
   end subroutine test_large_file

   subroutine test_missing(error)
      type(error_type), allocatable, intent(out) :: error
      type(line_type), allocatable :: lines(:)
      type(fd_error_type), allocatable :: err

      call read_text_file('no/such/file.txt', lines, err)
      call check(error, allocated(err), "a missing file must be an error")
      if (allocated(error)) return
      call check(error, index(err%message, 'no/such/file.txt') > 0, "message names the file: "//err%message)
   end subroutine test_missing

   !> A directory is not read as an empty file: the message says it is a directory.
   subroutine test_directory(error)
      type(error_type), allocatable, intent(out) :: error
      type(line_type), allocatable :: lines(:)
      type(fd_error_type), allocatable :: err

      call read_text_file('.', lines, err)
      call check(error, allocated(err), "a directory must be an error")
      if (allocated(error)) return
      call check(error, err%message, "'.' is a directory, not a file")
   end subroutine test_directory

   !> A NUL byte makes the file binary: an error naming the file and the line.
   subroutine test_nul(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: path = 'test_fd_textio_nul.tmp'
      type(line_type), allocatable :: lines(:)
      type(fd_error_type), allocatable :: err
      integer :: unit

      open (newunit=unit, file=path, access='stream', form='unformatted', status='replace')
      write (unit) 'line 1'//achar(10)//'line'//achar(0)//'2'//achar(10)
      close (unit)
      call read_text_file(path, lines, err)
      open (newunit=unit, file=path, status='old')
      close (unit, status='delete')
      call check(error, allocated(err), "a NUL character must be an error")
      if (allocated(error)) return
      call check(error, err%message, "file '"//path//"', line 2: a NUL character (byte 0): not a text file")
   end subroutine test_nul

   !> An empty file has no lines, and no error.
   subroutine test_empty(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: path = 'test_fd_textio_empty.tmp'
      type(line_type), allocatable :: lines(:)
      type(fd_error_type), allocatable :: err
      integer :: unit

      open (newunit=unit, file=path, access='stream', form='unformatted', status='replace')
      close (unit)
      call read_text_file(path, lines, err)
      open (newunit=unit, file=path, status='old')
      close (unit, status='delete')
      call check(error, .not. allocated(err), "an empty file is read")
      if (allocated(error)) return
      call check(error, size(lines), 0)
   end subroutine test_empty

   !> A text whose lines end with CR alone (CRs, no LF) is said to be one; LF and CR LF line
   !> ends are not.
   subroutine test_lone_cr(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: cr = achar(13), lf = achar(10)

      call check(error, index(cr_line_ends('a'//cr//'b'//cr), ': its lines end with CR alone') == 1, &
                 'CR-only line ends')
      if (allocated(error)) return
      call check(error, len_trim(cr_line_ends('a'//cr//lf//'b'//lf)), 0, 'CR LF and LF: nothing to say')
      if (allocated(error)) return
      call check(error, len_trim(cr_line_ends('a b')), 0, 'one line without an end: nothing to say')
   end subroutine test_lone_cr

   !> fmt_text: a text of at most 80 characters as it is (control characters as '?'); a
   !> longer one cut after 80 characters, never inside a UTF-8 character, and its length said.
   subroutine test_echo(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: e_acute = achar(195)//achar(169)

      call check(error, trim(fmt_text('abc'//achar(9)//'d')), 'abc?d')
      if (allocated(error)) return
      call check(error, trim(fmt_text(repeat('x', 80))), repeat('x', 80))
      if (allocated(error)) return
      call check(error, trim(fmt_text(repeat('x', 81))), repeat('x', 80)//'... (81 characters)')
      if (allocated(error)) return
      call check(error, trim(fmt_text(repeat('y', 1000000))), repeat('y', 80)//'... (1000000 characters)')
      if (allocated(error)) return
      call check(error, trim(fmt_text(repeat(e_acute, 100))), repeat(e_acute, 80)//'... (100 characters)')
      if (allocated(error)) return
      call check(error, trim(fmt_text('x'//repeat(e_acute, 80))), 'x'//repeat(e_acute, 79)//'... (81 characters)')
      if (allocated(error)) return
      call check(error, trim(fmt_text(repeat(achar(128), 400))), repeat(achar(128), 320)//'... (400 bytes)', &
                 'bytes that are no UTF-8 text')
   end subroutine test_echo

end module test_fd_textio
