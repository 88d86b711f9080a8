!> Matrix Market coordinate files: what scipy.io.mmwrite writes (general and symmetric, real,
!> integer and pattern fields, comments, CRLF) read entry by entry, and every malformed file
!> refused with its line.
module test_fd_matrix_market
   use testdrive, only: new_unittest, unittest_type, error_type, check, test_failed
   use fd_kinds, only: dp
   use fd_error, only: lib_error => error_type
   use fd_textio, only: line_type, split_lines
   use fd_matrix_market, only: sparse_matrix, parse_matrix_market, symmetric_entries, read_matrix_market
   implicit none
   private

   public :: collect_matrix_market

   character(len=*), parameter :: nl = achar(10)

contains

   subroutine collect_matrix_market(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("scipy's symmetric real file", test_symmetric), &
                  new_unittest("general, integer and pattern fields", test_fields), &
                  new_unittest("malformed files named with their line", test_errors), &
                  new_unittest("a missing file", test_missing) &
                  ]
   end subroutine collect_matrix_market

   subroutine parse(text, mat, err)
      character(len=*), intent(in) :: text
      type(sparse_matrix), intent(out) :: mat
      type(lib_error), allocatable, intent(out) :: err
      type(line_type), allocatable :: lines(:)
      integer :: stat

      call split_lines(text, lines, stat)
      if (stat /= 0) error stop "parse: no memory"
      call parse_matrix_market('k.mtx', lines, mat, err)
   end subroutine parse

   !> The stiffness of two storeys, k1 = 3e7 and k2 = 2e7 N/m, as scipy.io.mmwrite writes a
   !> symmetric matrix (lower triangle, 17 significant digits), with CRLF line ends.
   subroutine test_symmetric(error)
      type(error_type), allocatable, intent(out) :: error
      type(sparse_matrix) :: mat
      type(lib_error), allocatable :: err
      integer, allocatable :: row(:), col(:)
      real(dp), allocatable :: val(:)
      real(dp) :: k(2, 2)
      integer :: e, stat
      character(len=*), parameter :: cr = achar(13)

      call parse("%%MatrixMarket matrix coordinate real symmetric"//cr//nl// &
                 "%"//cr//nl// &
                 "2 2 3"//cr//nl// &
                 "1 1 5.0000000000000000e+07"//cr//nl// &
                 "2 1 -2.0000000000000000e+07"//cr//nl// &
                 "2 2 2.0000000000000000e+07"//cr//nl, mat, err)
      if (allocated(err)) then
         call test_failed(error, err%message)
         return
      end if
      call check(error, mat%symmetric .and. mat%n_rows == 2 .and. mat%n_cols == 2 .and. mat%nnz == 3, "size")
      if (allocated(error)) return
      call symmetric_entries(mat, row, col, val, stat)
      call check(error, stat == 0 .and. size(val) == 4, "the off-diagonal entry mirrored")
      if (allocated(error)) return
      k = 0.0_dp
      do e = 1, size(val)
         k(row(e), col(e)) = k(row(e), col(e)) + val(e)
      end do
      call check(error, all(k == reshape([5.0e7_dp, -2.0e7_dp, -2.0e7_dp, 2.0e7_dp], [2, 2])), "K exactly")
   end subroutine test_symmetric

   subroutine test_fields(error)
      type(error_type), allocatable, intent(out) :: error
      type(sparse_matrix) :: mat
      type(lib_error), allocatable :: err

      ! a general (non-square) integer matrix, comments and blank lines between the entries
      call parse("%%MatrixMarket matrix coordinate integer general"//nl//"% from a test"//nl//nl// &
                 "2 3 2"//nl//"1 3 7"//nl//"% a comment"//nl//nl//"2 1 -4"//nl, mat, err)
      if (allocated(err)) then
         call test_failed(error, err%message)
         return
      end if
      call check(error, .not. mat%symmetric .and. mat%n_cols == 3 .and. all(mat%row == [1, 2]) .and. &
                 all(mat%col == [3, 1]) .and. all(mat%val == [7.0_dp, -4.0_dp]), "integer general")
      if (allocated(error)) return
      ! a pattern: every entry is 1; the header's words in any case
      call parse("%%MatrixMarket Matrix Coordinate Pattern General"//nl//"3 3 2"//nl//"1 1"//nl//"3 2"//nl, &
                 mat, err)
      if (allocated(err)) then
         call test_failed(error, err%message)
         return
      end if
      call check(error, all(mat%val == 1.0_dp) .and. all(mat%row == [1, 3]), "pattern")
   end subroutine test_fields

   subroutine test_errors(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: sym = "%%MatrixMarket matrix coordinate real symmetric"//nl
      character(len=*), parameter :: gen = "%%MatrixMarket matrix coordinate real general"//nl

      call expect("", "k.mtx: the file is empty", error)
      if (allocated(error)) return
      call expect("1 1 1"//nl, "k.mtx, line 1: '1 1 1': not a Matrix Market header", error)
      if (allocated(error)) return
      call expect("%%MatrixMarket matrix array real general"//nl//"2 2"//nl, &
                  "the format 'array' is not read: only 'coordinate'", error)
      if (allocated(error)) return
      call expect("%%MatrixMarket matrix coordinate complex general"//nl, "the field 'complex' is not read", error)
      if (allocated(error)) return
      call expect("%%MatrixMarket matrix coordinate real skew-symmetric"//nl, &
                  "the symmetry 'skew-symmetric' is not read", error)
      if (allocated(error)) return
      call expect(sym//"% only comments"//nl, "no size line", error)
      if (allocated(error)) return
      call expect(sym//"2 2"//nl, "line 2: '2 2': the size line must be three whole numbers", error)
      if (allocated(error)) return
      call expect(sym//"2 3 1"//nl//"1 1 1.0"//nl, "line 2: '2 3 1': a symmetric matrix is square", error)
      if (allocated(error)) return
      call expect(sym//"2 2 2"//nl//"1 1 1.0"//nl//"1 2 3.0"//nl, &
                  "line 4: '1 2 3.0': (1, 2) is above the diagonal; a symmetric file holds the lower triangle", error)
      if (allocated(error)) return
      call expect(gen//"2 2 1"//nl//"3 1 1.0"//nl, "line 3: '3 1 1.0': (3, 1) is outside the 2 x 2 matrix", error)
      if (allocated(error)) return
      call expect(gen//"2 2 1"//nl//"1 1 nan"//nl, "line 3: '1 1 nan': the value 'nan' is not a finite number", &
                  error)
      if (allocated(error)) return
      call expect(gen//"2 2 1"//nl//"1 1.5 2.0"//nl, "line 3: '1 1.5 2.0': an entry must be 'i j value'", error)
      if (allocated(error)) return
      call expect(gen//"2 2 1"//nl//"1 1 2.0 7"//nl, "an entry must be 'i j value'", error)
      if (allocated(error)) return
      call expect(gen//"2 2 3"//nl//"1 1 2.0"//nl//"2 2 1.0"//nl, &
                  "k.mtx: 2 entries where the size line (line 2) gives 3: the file is cut short", error)
      if (allocated(error)) return
      call expect(gen//"2 2 1"//nl//"1 1 2.0"//nl//"2 2 1.0"//nl, &
                  "line 4: '2 2 1.0': more entries than the 1 of the size line (line 2)", error)
      if (allocated(error)) return
      call expect(gen//"2 2 3"//nl//"2 1 2.0"//nl//"1 1 1.0"//nl//"2 1 4.0"//nl, &
                  "the entry (2, 1) is given twice (entries 1 and 3)", error)
   end subroutine test_errors

   subroutine test_missing(error)
      type(error_type), allocatable, intent(out) :: error
      type(sparse_matrix) :: mat
      type(lib_error), allocatable :: err

      call read_matrix_market('no/such/k.mtx', mat, err)
      call check(error, allocated(err), "a missing file is an error")
      if (allocated(error)) return
      call check(error, index(err%message, 'no/such/k.mtx') > 0, "the message names the file: "//err%message)
   end subroutine test_missing

   subroutine expect(text, words, error)
      character(len=*), intent(in) :: text, words
      type(error_type), allocatable, intent(out) :: error
      type(sparse_matrix) :: mat
      type(lib_error), allocatable :: err

      call parse(text, mat, err)
      if (.not. allocated(err)) then
         call test_failed(error, "accepted: "//text)
         return
      end if
      call check(error, index(err%message, words) > 0, "'"//err%message//"' does not contain '"//words//"'")
   end subroutine expect

end module test_fd_matrix_market
