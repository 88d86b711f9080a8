!> SHA-256 (FIPS 180-4) of bytes, for the summary's provenance: the hash of the deck and of
!> the record a run read (the bytes the readers read), the hex digest `sha256sum FILE` prints.
!>
!> The words are held in default 32-bit integers and added modulo 2**32 through 64-bit
!> integers (Fortran has no unsigned type and signed overflow is not defined); rotations and
!> shifts act on the bit pattern. A digest is built incrementally (sha256_init, sha256_update
!> any number of times, sha256_final) or at once (sha256_text).
module fd_sha256
   use, intrinsic :: iso_fortran_env, only: int32, int64
   implicit none
   private

   public :: sha256_state, sha256_init, sha256_update, sha256_final, sha256_text

   integer(int64), parameter :: k64(64) = [ &
      int(z'428a2f98', int64), int(z'71374491', int64), int(z'b5c0fbcf', int64), int(z'e9b5dba5', int64), &
      int(z'3956c25b', int64), int(z'59f111f1', int64), int(z'923f82a4', int64), int(z'ab1c5ed5', int64), &
      int(z'd807aa98', int64), int(z'12835b01', int64), int(z'243185be', int64), int(z'550c7dc3', int64), &
      int(z'72be5d74', int64), int(z'80deb1fe', int64), int(z'9bdc06a7', int64), int(z'c19bf174', int64), &
      int(z'e49b69c1', int64), int(z'efbe4786', int64), int(z'0fc19dc6', int64), int(z'240ca1cc', int64), &
      int(z'2de92c6f', int64), int(z'4a7484aa', int64), int(z'5cb0a9dc', int64), int(z'76f988da', int64), &
      int(z'983e5152', int64), int(z'a831c66d', int64), int(z'b00327c8', int64), int(z'bf597fc7', int64), &
      int(z'c6e00bf3', int64), int(z'd5a79147', int64), int(z'06ca6351', int64), int(z'14292967', int64), &
      int(z'27b70a85', int64), int(z'2e1b2138', int64), int(z'4d2c6dfc', int64), int(z'53380d13', int64), &
      int(z'650a7354', int64), int(z'766a0abb', int64), int(z'81c2c92e', int64), int(z'92722c85', int64), &
      int(z'a2bfe8a1', int64), int(z'a81a664b', int64), int(z'c24b8b70', int64), int(z'c76c51a3', int64), &
      int(z'd192e819', int64), int(z'd6990624', int64), int(z'f40e3585', int64), int(z'106aa070', int64), &
      int(z'19a4c116', int64), int(z'1e376c08', int64), int(z'2748774c', int64), int(z'34b0bcb5', int64), &
      int(z'391c0cb3', int64), int(z'4ed8aa4a', int64), int(z'5b9cca4f', int64), int(z'682e6ff3', int64), &
      int(z'748f82ee', int64), int(z'78a5636f', int64), int(z'84c87814', int64), int(z'8cc70208', int64), &
      int(z'90befffa', int64), int(z'a4506ceb', int64), int(z'bef9a3f7', int64), int(z'c67178f2', int64)]
   integer(int64), parameter :: two32 = 4294967296_int64
   integer(int32), parameter :: k256(64) = int(k64 - merge(two32, 0_int64, k64 > 2147483647_int64), int32)

   integer(int64), parameter :: h64(8) = [ &
      int(z'6a09e667', int64), int(z'bb67ae85', int64), int(z'3c6ef372', int64), int(z'a54ff53a', int64), &
      int(z'510e527f', int64), int(z'9b05688c', int64), int(z'1f83d9ab', int64), int(z'5be0cd19', int64)]
   integer(int32), parameter :: h0(8) = int(h64 - merge(two32, 0_int64, h64 > 2147483647_int64), int32)

   integer(int64), parameter :: mask32 = int(z'FFFFFFFF', int64)

   !> A digest in progress.
   type :: sha256_state
      integer(int32) :: h(8) = h0           !! the hash words
      character(len=64) :: block = ''       !! bytes of the block being filled
      integer :: fill = 0                   !! bytes in block
      integer(int64) :: length = 0          !! bytes hashed so far
   end type sha256_state

contains

   !> A fresh digest.
   pure subroutine sha256_init(st)
      type(sha256_state), intent(out) :: st !! the digest, empty
      st%fill = 0
   end subroutine sha256_init

   !> Add bytes to a digest.
   pure subroutine sha256_update(st, bytes)
      type(sha256_state), intent(inout) :: st  !! the digest
      character(len=*), intent(in) :: bytes    !! the bytes to add
      integer :: i, take

      i = 1
      do while (i <= len(bytes))
         take = min(64 - st%fill, len(bytes) - i + 1)
         st%block(st%fill + 1:st%fill + take) = bytes(i:i + take - 1)
         st%fill = st%fill + take
         i = i + take
         if (st%fill == 64) then
            call compress(st%h, st%block)
            st%fill = 0
         end if
      end do
      st%length = st%length + len(bytes)
   end subroutine sha256_update

   !> Finish a digest: its 64 lower-case hex digits.
   pure subroutine sha256_final(st, hex)
      type(sha256_state), intent(inout) :: st  !! the digest (finished: not to be updated again)
      character(len=64), intent(out) :: hex    !! the hash in hex
      character(len=*), parameter :: digits = '0123456789abcdef'
      character(len=8) :: tail
      integer(int64) :: bits
      integer :: i, j, nib

      bits = st%length*8_int64
      st%block(st%fill + 1:st%fill + 1) = char(128)
      st%fill = st%fill + 1
      if (st%fill > 56) then
         st%block(st%fill + 1:) = repeat(char(0), 64 - st%fill)
         call compress(st%h, st%block)
         st%fill = 0
      end if
      st%block(st%fill + 1:56) = repeat(char(0), 56 - st%fill)
      do i = 1, 8
         tail(i:i) = char(int(iand(shiftr(bits, 8*(8 - i)), 255_int64)))
      end do
      st%block(57:64) = tail
      call compress(st%h, st%block)
      st%fill = 0
      do i = 1, 8
         do j = 1, 8
            nib = int(iand(shiftr(int(st%h(i), int64), 4*(8 - j)), 15_int64))
            hex(8*(i - 1) + j:8*(i - 1) + j) = digits(nib + 1:nib + 1)
         end do
      end do
   end subroutine sha256_final

   !> SHA-256 of a text (its bytes as they are).
   pure subroutine sha256_text(text, hex)
      character(len=*), intent(in) :: text     !! the bytes
      character(len=64), intent(out) :: hex    !! the hash in hex
      type(sha256_state) :: st

      call sha256_init(st)
      call sha256_update(st, text)
      call sha256_final(st, hex)
   end subroutine sha256_text

   !> One 64-byte block into the hash words.
   pure subroutine compress(h, block)
      integer(int32), intent(inout) :: h(8)
      character(len=64), intent(in) :: block
      integer(int32) :: w(64), a, b, c, d, e, f, g, hh, s0, s1, ch, maj, t1, t2
      integer :: i

      do i = 1, 16
         w(i) = word(block(4*i - 3:4*i))
      end do
      do i = 17, 64
         s0 = ieor(ieor(ishftc(w(i - 15), -7), ishftc(w(i - 15), -18)), shiftr(w(i - 15), 3))
         s1 = ieor(ieor(ishftc(w(i - 2), -17), ishftc(w(i - 2), -19)), shiftr(w(i - 2), 10))
         w(i) = add(add(w(i - 16), s0), add(w(i - 7), s1))
      end do
      a = h(1); b = h(2); c = h(3); d = h(4); e = h(5); f = h(6); g = h(7); hh = h(8)
      do i = 1, 64
         s1 = ieor(ieor(ishftc(e, -6), ishftc(e, -11)), ishftc(e, -25))
         ch = ieor(iand(e, f), iand(not(e), g))
         t1 = add(add(add(hh, s1), add(ch, k256(i))), w(i))
         s0 = ieor(ieor(ishftc(a, -2), ishftc(a, -13)), ishftc(a, -22))
         maj = ieor(ieor(iand(a, b), iand(a, c)), iand(b, c))
         t2 = add(s0, maj)
         hh = g; g = f; f = e
         e = add(d, t1)
         d = c; c = b; b = a
         a = add(t1, t2)
      end do
      h = [add(h(1), a), add(h(2), b), add(h(3), c), add(h(4), d), add(h(5), e), add(h(6), f), &
           add(h(7), g), add(h(8), hh)]
   end subroutine compress

   !> x + y modulo 2**32, on the bit patterns.
   elemental integer(int32) function add(x, y)
      integer(int32), intent(in) :: x, y
      integer(int64) :: s

      s = iand(iand(int(x, int64), mask32) + iand(int(y, int64), mask32), mask32)
      add = int(s - merge(two32, 0_int64, s > 2147483647_int64), int32)
   end function add

   !> Four bytes, big-endian, as a word.
   pure integer(int32) function word(bytes)
      character(len=4), intent(in) :: bytes
      integer(int64) :: s
      integer :: i

      s = 0
      do i = 1, 4
         s = ior(shiftl(s, 8), int(ichar(bytes(i:i)), int64))
      end do
      word = int(s - merge(two32, 0_int64, s > 2147483647_int64), int32)
   end function word

end module fd_sha256
