!> Matrix Market files in the coordinate format (what scipy.io.mmwrite and many finite-element
!> codes write): a header `%%MatrixMarket matrix coordinate FIELD SYMMETRY`, comment lines
!> starting with %, a size line `rows cols entries`, then one `i j value` line per entry
!> (`i j` for the pattern field). FIELD is real, integer or pattern (a pattern entry is 1);
!> SYMMETRY is general or symmetric (the file holds the lower triangle, i >= j, as the
!> format's definition says). complex, hermitian, skew-symmetric and the dense array format
!> are refused, as is anything the format does not allow: an index outside the size, an
!> upper-triangle entry of a symmetric file, a value that is not finite, fewer or more
!> entries than the size line gives. An entry given twice is an error too (the format has
!> one line per entry; an assembly that sums duplicates is the writer's to do). Lines may
!> end in CRLF.
module fd_matrix_market
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_text, stat_no_memory
   use fd_textio, only: line_type, read_text_file, lower, split_tokens
   use fd_record, only: parse_real
   use fd_sort, only: sort_keys, stable_order
   implicit none
   private

   public :: sparse_matrix, read_matrix_market, parse_matrix_market, symmetric_entries

   !> A sparse matrix as its entries (coordinate form), as the file gives them.
   type :: sparse_matrix
      integer :: n_rows = 0                 !! rows
      integer :: n_cols = 0                 !! columns
      integer :: nnz = 0                    !! entries stored
      logical :: symmetric = .false.        !! only the lower triangle is stored (i >= j)
      integer, allocatable :: row(:)        !! row of each entry (1..n_rows)
      integer, allocatable :: col(:)        !! column of each entry (1..n_cols)
      real(dp), allocatable :: val(:)       !! value of each entry
   end type sparse_matrix

   !> The positions of a matrix's entries, which check_duplicates sorts them by.
   type, extends(sort_keys) :: position_keys
      integer, allocatable :: row(:), col(:)   !! each entry's row and column
   contains
      procedure :: before => position_before
   end type position_keys

contains

   !> Read a Matrix Market coordinate file.
   subroutine read_matrix_market(path, mat, error)
      character(len=*), intent(in) :: path               !! the file
      type(sparse_matrix), intent(out) :: mat            !! its matrix
      type(error_type), allocatable, intent(out) :: error !! what is wrong, with the line
      type(line_type), allocatable :: lines(:)

      call read_text_file(path, lines, error)
      if (allocated(error)) return
      call parse_matrix_market(path, lines, mat, error)
   end subroutine read_matrix_market

   !> A Matrix Market coordinate file's lines as a matrix; messages start with path and the
   !> line's number.
   subroutine parse_matrix_market(path, lines, mat, error)
      character(len=*), intent(in) :: path               !! the file (for messages)
      type(line_type), intent(in) :: lines(:)            !! its lines
      type(sparse_matrix), intent(out) :: mat            !! its matrix
      type(error_type), allocatable, intent(out) :: error !! what is wrong, with the line
      logical :: pattern
      integer :: l, nsize, k, stat

      call read_header(path, lines, pattern, mat%symmetric, error)
      if (allocated(error)) return
      ! the size line: the first after the comments (blank lines are allowed before it)
      l = 2
      do while (l <= size(lines))
         if (.not. skipped(lines(l)%s)) exit
         l = l + 1
      end do
      if (l > size(lines)) then
         call fatal_error(error, path//": no size line ('rows columns entries') after the header")
         return
      end if
      call read_size(path, l, without_cr(lines(l)%s), mat, error)
      if (allocated(error)) return
      nsize = l
      allocate (mat%row(mat%nnz), mat%col(mat%nnz), mat%val(mat%nnz), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, path//", line "//trim(fmt_int(nsize))//": not enough memory for "// &
                          trim(fmt_int(mat%nnz))//" entries", stat_no_memory)
         return
      end if
      k = 0
      do l = nsize + 1, size(lines)
         if (skipped(lines(l)%s)) cycle
         k = k + 1
         if (k > mat%nnz) then
            call fatal_error(error, path//", line "//trim(fmt_int(l))//": '"//trim(fmt_text(lines(l)%s))// &
                             "': more entries than the "//trim(fmt_int(mat%nnz))//" of the size line (line "// &
                             trim(fmt_int(nsize))//")")
            return
         end if
         call read_entry(path, l, without_cr(lines(l)%s), pattern, mat, k, error)
         if (allocated(error)) return
      end do
      if (k < mat%nnz) then
         call fatal_error(error, path//": "//trim(fmt_int(k))//" entries where the size line (line "// &
                          trim(fmt_int(nsize))//") gives "//trim(fmt_int(mat%nnz))//": the file is cut short")
         return
      end if
      call check_duplicates(path, mat, error)
   end subroutine parse_matrix_market

   !> A line without the carriage return a CRLF file ends it with.
   pure function without_cr(s) result(t)
      character(len=*), intent(in) :: s
      character(len=max(len(s) - merge(1, 0, len(s) > 0 .and. index(s, achar(13), back=.true.) == len(s)), 0)) :: t

      t = s(1:len(t))
   end function without_cr

   !> A comment or a blank line.
   pure logical function skipped(s)
      character(len=*), intent(in) :: s
      integer :: i

      i = verify(s, ' '//achar(9)//achar(13))
      skipped = i == 0
      if (.not. skipped) skipped = s(i:i) == '%'
   end function skipped

   !> `%%MatrixMarket matrix coordinate FIELD SYMMETRY` (case-insensitive).
   subroutine read_header(path, lines, pattern, symmetric, error)
      character(len=*), intent(in) :: path
      type(line_type), intent(in) :: lines(:)
      logical, intent(out) :: pattern, symmetric
      type(error_type), allocatable, intent(out) :: error
      type(line_type), allocatable :: w(:)
      character(len=*), parameter :: form = "'%%MatrixMarket matrix coordinate real|integer|pattern " // &
                                            "general|symmetric'"
      character(len=*), parameter :: part(2) = [character(len=8) :: 'field', 'symmetry']
      ! the words each part may be (a blank fills the symmetry's column: no token is blank)
      character(len=*), parameter :: words(3, 2) = reshape([character(len=9) :: 'real', 'integer', 'pattern', &
                                                            'general', 'symmetric', ''], [3, 2])
      character(len=*), parameter :: allowed(2) = [character(len=24) :: 'real, integer or pattern', &
                                                   'general or symmetric']
      integer :: choice(2), q, k

      pattern = .false.
      symmetric = .false.
      if (size(lines) == 0) then
         call fatal_error(error, path//": the file is empty; a Matrix Market file starts with "//form)
         return
      end if
      call split_tokens(lower(without_cr(lines(1)%s)), w)
      if (size(w) /= 5) then
         call header_error("not a Matrix Market header, which reads "//form)
         return
      end if
      if (w(1)%s /= '%%matrixmarket' .or. w(2)%s /= 'matrix') then
         call header_error("not a Matrix Market header, which reads "//form)
         return
      end if
      if (w(3)%s /= 'coordinate') then
         call header_error("the format '"//w(3)%s//"' is not read: only 'coordinate' (sparse)")
         return
      end if
      ! the field, then the symmetry: each one of the words of its column
      do q = 1, 2
         choice(q) = 0
         do k = 1, size(words, 1)
            if (words(k, q) == w(3 + q)%s) choice(q) = k
         end do
         if (choice(q) == 0) then
            call header_error("the "//trim(part(q))//" '"//trim(fmt_text(w(3 + q)%s))//"' is not read: "// &
                              trim(allowed(q)))
            return
         end if
      end do
      pattern = choice(1) == 3
      symmetric = choice(2) == 2
   contains
      subroutine header_error(what)
         character(len=*), intent(in) :: what
         call fatal_error(error, path//", line 1: '"//trim(fmt_text(lines(1)%s))//"': "//what)
      end subroutine header_error
   end subroutine read_header

   !> `rows columns entries`.
   subroutine read_size(path, l, s, mat, error)
      character(len=*), intent(in) :: path, s
      integer, intent(in) :: l
      type(sparse_matrix), intent(inout) :: mat
      type(error_type), allocatable, intent(out) :: error
      type(line_type), allocatable :: w(:)
      integer :: v(3), k
      logical :: ok

      call split_tokens(s, w)
      ok = size(w) == 3
      if (ok) then
         do k = 1, 3
            call parse_count(w(k)%s, v(k), ok)
            if (.not. ok) exit
         end do
      end if
      if (.not. ok) then
         call fatal_error(error, path//", line "//trim(fmt_int(l))//": '"//trim(fmt_text(s))// &
                          "': the size line must be three whole numbers, 'rows columns entries'")
         return
      end if
      if (v(1) < 1 .or. v(2) < 1) then
         call fatal_error(error, path//", line "//trim(fmt_int(l))//": '"//trim(fmt_text(s))// &
                          "': a matrix has at least one row and one column")
         return
      end if
      if (mat%symmetric .and. v(1) /= v(2)) then
         call fatal_error(error, path//", line "//trim(fmt_int(l))//": '"//trim(fmt_text(s))// &
                          "': a symmetric matrix is square")
         return
      end if
      mat%n_rows = v(1)
      mat%n_cols = v(2)
      mat%nnz = v(3)
   end subroutine read_size

   !> `i j value` (or `i j` for a pattern) into entry k.
   subroutine read_entry(path, l, s, pattern, mat, k, error)
      character(len=*), intent(in) :: path, s
      integer, intent(in) :: l, k
      logical, intent(in) :: pattern
      type(sparse_matrix), intent(inout) :: mat
      type(error_type), allocatable, intent(out) :: error
      type(line_type), allocatable :: w(:)
      integer :: i, j, stat, want
      logical :: ok

      call split_tokens(s, w)
      want = merge(2, 3, pattern)
      ok = size(w) == want
      if (ok) call parse_count(w(1)%s, i, ok)
      if (ok) call parse_count(w(2)%s, j, ok)
      if (.not. ok) then
         call entry_error("an entry must be '"//merge("i j      ", "i j value", pattern)//"' (whole i and j)")
         return
      end if
      if (i < 1 .or. i > mat%n_rows .or. j < 1 .or. j > mat%n_cols) then
         call entry_error("("//trim(fmt_int(i))//", "//trim(fmt_int(j))//") is outside the "// &
                          trim(fmt_int(mat%n_rows))//" x "//trim(fmt_int(mat%n_cols))//" matrix")
         return
      end if
      if (mat%symmetric .and. i < j) then
         call entry_error("("//trim(fmt_int(i))//", "//trim(fmt_int(j))//") is above the diagonal; a symmetric "// &
                          "file holds the lower triangle (i >= j)")
         return
      end if
      mat%row(k) = i
      mat%col(k) = j
      mat%val(k) = 1.0_dp
      if (pattern) return
      call parse_real(w(3)%s, mat%val(k), stat)
      if (stat /= 0) then
         call entry_error("the value '"//trim(fmt_text(w(3)%s))//"' is not a finite number")
         return
      end if
   contains
      subroutine entry_error(what)
         character(len=*), intent(in) :: what
         call fatal_error(error, path//", line "//trim(fmt_int(l))//": '"//trim(fmt_text(s))//"': "//what)
      end subroutine entry_error
   end subroutine read_entry

   !> A whole number of at most 9 digits, with an optional + sign.
   pure subroutine parse_count(tok, v, ok)
      character(len=*), intent(in) :: tok
      integer, intent(out) :: v
      logical, intent(out) :: ok
      integer :: i, i0

      v = 0
      i0 = 1
      if (len(tok) > 0) then
         if (tok(1:1) == '+') i0 = 2
      end if
      ok = len(tok) >= i0 .and. len(tok) - i0 + 1 <= 9
      if (.not. ok) return
      do i = i0, len(tok)
         if (tok(i:i) < '0' .or. tok(i:i) > '9') then
            ok = .false.
            return
         end if
         v = 10*v + (iachar(tok(i:i)) - iachar('0'))
      end do
   end subroutine parse_count

   !> No position given twice (sorted by row and column, stable_order: O(nnz log nnz)).
   subroutine check_duplicates(path, mat, error)
      character(len=*), intent(in) :: path
      type(sparse_matrix), intent(in) :: mat
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: key_order(:)
      type(position_keys) :: keys
      integer :: k, a, b, stat

      allocate (key_order(mat%nnz), keys%row(mat%nnz), keys%col(mat%nnz), stat=stat)
      if (stat == 0) then
         keys%row = mat%row
         keys%col = mat%col
         key_order = [(k, k=1, mat%nnz)]
         call stable_order(keys, key_order, stat)
      end if
      if (stat /= 0) then
         call fatal_error(error, path//": not enough memory to check "//trim(fmt_int(mat%nnz))//" entries", &
                          stat_no_memory)
         return
      end if
      do k = 2, mat%nnz
         a = key_order(k - 1)
         b = key_order(k)
         if (mat%row(a) == mat%row(b) .and. mat%col(a) == mat%col(b)) then
            call fatal_error(error, path//": the entry ("//trim(fmt_int(mat%row(a)))//", "// &
                             trim(fmt_int(mat%col(a)))//") is given twice (entries "// &
                             trim(fmt_int(min(a, b)))//" and "//trim(fmt_int(max(a, b)))// &
                             "); sum duplicates when the matrix is written")
            return
         end if
      end do
   end subroutine check_duplicates

   !> Whether entry a's position comes before entry b's (by row, then column).
   pure logical function position_before(keys, a, b) result(before)
      class(position_keys), intent(in) :: keys   !! the entries' positions
      integer, intent(in) :: a, b                !! two entries

      before = keys%row(a) < keys%row(b) .or. (keys%row(a) == keys%row(b) .and. keys%col(a) < keys%col(b))
   end function position_before

   !> The entries of the whole matrix: a symmetric file's off-diagonal entries mirrored
   !> (i, j) -> (j, i); a general file's as they are.
   subroutine symmetric_entries(mat, row, col, val, stat)
      type(sparse_matrix), intent(in) :: mat          !! the matrix as read
      integer, allocatable, intent(out) :: row(:)     !! rows of all entries
      integer, allocatable, intent(out) :: col(:)     !! their columns
      real(dp), allocatable, intent(out) :: val(:)    !! their values
      integer, intent(out) :: stat                    !! 0, or the allocation's status
      integer :: k, m, n

      n = mat%nnz
      if (mat%symmetric) n = n + count(mat%row(1:mat%nnz) /= mat%col(1:mat%nnz))
      allocate (row(n), col(n), val(n), stat=stat)
      if (stat /= 0) return
      m = 0
      do k = 1, mat%nnz
         m = m + 1
         row(m) = mat%row(k); col(m) = mat%col(k); val(m) = mat%val(k)
         if (mat%symmetric .and. mat%row(k) /= mat%col(k)) then
            m = m + 1
            row(m) = mat%col(k); col(m) = mat%row(k); val(m) = mat%val(k)
         end if
      end do
   end subroutine symmetric_entries

end module fd_matrix_market
