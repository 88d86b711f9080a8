!> Unit tests of SHA-256 (fd_sha256): the FIPS 180-4 example messages (one block, two
!> blocks, a million 'a'), the padding boundaries (55, 56, 64 bytes), bytes above 127, the
!> digest built in pieces, and a file's bytes as the readers read them (fd_textio).
module test_fd_sha256
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_error, only: fd_error_type => error_type
   use fd_sha256, only: sha256_state, sha256_init, sha256_update, sha256_final, sha256_text
   use fd_textio, only: read_file_text
   implicit none
   private

   public :: collect_sha256

contains

   subroutine collect_sha256(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("FIPS 180-4 examples", test_fips), &
                  new_unittest("padding boundaries and high bytes", test_padding), &
                  new_unittest("a digest built in pieces", test_pieces), &
                  new_unittest("a file", test_file) &
                  ]
   end subroutine collect_sha256

   subroutine test_fips(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=64) :: hex
      type(sha256_state) :: st
      integer :: i

      call sha256_text('', hex)
      call check(error, hex, 'e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855')
      if (allocated(error)) return
      call sha256_text('abc', hex)
      call check(error, hex, 'ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad')
      if (allocated(error)) return
      call sha256_text('abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq', hex)
      call check(error, hex, '248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1')
      if (allocated(error)) return
      call sha256_init(st)
      do i = 1, 1000
         call sha256_update(st, repeat('a', 1000))
      end do
      call sha256_final(st, hex)
      call check(error, hex, 'cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0')
   end subroutine test_fips

   !> Digests from Python's hashlib (the messages 'x' * 55, 'x' * 56, 'x' * 64, and UTF-8 'héllo').
   subroutine test_padding(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=64) :: hex

      call sha256_text(repeat('x', 55), hex)
      call check(error, hex, 'd5e285683cd4efc02d021a5c62014694958901005d6f71e89e0989fac77e4072')
      if (allocated(error)) return
      call sha256_text(repeat('x', 56), hex)
      call check(error, hex, '04c26261370ee7541549d16dee320c723e3fd14671e66a099afe0a377c16888e')
      if (allocated(error)) return
      call sha256_text(repeat('x', 64), hex)
      call check(error, hex, '7ce100971f64e7001e8fe5a51973ecdfe1ced42befe7ee8d5fd6219506b5393c')
      if (allocated(error)) return
      call sha256_text('h'//char(195)//char(169)//'llo', hex)
      call check(error, hex, '3c48591d8d098a4538f5e013dfcf406e948eac4d3277b10bf614e295d6068179')
   end subroutine test_padding

   subroutine test_pieces(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=64) :: whole, parts
      character(len=200) :: text
      type(sha256_state) :: st
      integer :: i

      do i = 1, len(text)
         text(i:i) = achar(32 + mod(7*i, 90))
      end do
      call sha256_text(text, whole)
      call sha256_init(st)
      call sha256_update(st, text(1:1))
      call sha256_update(st, text(2:63))
      call sha256_update(st, text(64:64))
      call sha256_update(st, text(65:130))
      call sha256_update(st, text(131:))
      call sha256_final(st, parts)
      call check(error, parts, whole)
   end subroutine test_pieces

   !> The bytes read_file_text gives (what the deck and record readers hash), with a CR LF
   !> line end and no final newline, against hashlib's digest of the same bytes.
   subroutine test_file(error)
      type(error_type), allocatable, intent(out) :: error
      type(fd_error_type), allocatable :: err
      character(len=:), allocatable :: text
      character(len=64) :: hex
      character(len=*), parameter :: path = 'test_fd_sha256.tmp'
      integer :: unit

      open (newunit=unit, file=path, access='stream', form='unformatted', status='replace')
      write (unit) 'line one'//achar(13)//achar(10)//'line two'
      close (unit)
      call read_file_text(path, text, err)
      open (newunit=unit, file=path, status='old')
      close (unit, status='delete')
      call check(error, .not. allocated(err), 'the file is read')
      if (allocated(error)) return
      call sha256_text(text, hex)
      call check(error, hex, '8ec4c37982ffc5a839234595530d36fa868683bc09ea40fe9960cb64c7847e33')
   end subroutine test_file

end module test_fd_sha256
