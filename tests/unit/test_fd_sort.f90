!> Unit tests of the stable sort (fd_sort): items in the order of their keys, equal keys in
!> their first order, against an insertion sort; no item, one item, a reversed order.
module test_fd_sort
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_sort, only: sort_keys, stable_order
   implicit none
   private

   public :: collect_sort

   !> Items sorted by an integer key each.
   type, extends(sort_keys) :: integer_keys
      integer, allocatable :: key(:)
   contains
      procedure :: before => key_before
   end type integer_keys

contains

   subroutine collect_sort(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("equal keys keep their order", test_stable), &
                  new_unittest("no item, one item, reversed", test_small) &
                  ]
   end subroutine collect_sort

   pure logical function key_before(keys, a, b) result(before)
      class(integer_keys), intent(in) :: keys
      integer, intent(in) :: a, b
      before = keys%key(a) < keys%key(b)
   end function key_before

   !> 37 items with keys 0..4 (many equal), every size of run the merge meets: the order an
   !> insertion sort (stable) gives, item by item.
   subroutine test_stable(error)
      type(error_type), allocatable, intent(out) :: error
      type(integer_keys) :: keys
      integer, parameter :: n = 37
      integer :: order(n), expected(n), k, j, item, stat

      keys%key = [(mod(7*k + 3, 5), k=1, n)]
      order = [(k, k=1, n)]
      call stable_order(keys, order, stat)
      call check(error, stat, 0)
      if (allocated(error)) return
      do k = 1, n   ! insertion sort: an item goes after every item whose key is not larger
         item = k
         j = k - 1
         do while (j >= 1)
            if (.not. keys%key(item) < keys%key(expected(j))) exit
            expected(j + 1) = expected(j)
            j = j - 1
         end do
         expected(j + 1) = item
      end do
      call check(error, all(order == expected), "the stable order of 37 items")
      if (allocated(error)) return
      call check(error, all(keys%key(order(2:)) >= keys%key(order(:n - 1))), "keys ascending")
   end subroutine test_stable

   subroutine test_small(error)
      type(error_type), allocatable, intent(out) :: error
      type(integer_keys) :: keys
      integer, allocatable :: order(:)
      integer :: stat, k

      allocate (keys%key(0), order(0))
      call stable_order(keys, order, stat)
      call check(error, stat == 0 .and. size(order) == 0, "no item")
      if (allocated(error)) return
      keys%key = [4]
      order = [1]
      call stable_order(keys, order, stat)
      call check(error, stat == 0 .and. all(order == [1]), "one item")
      if (allocated(error)) return
      keys%key = [(10 - k, k=1, 9)]
      order = [(k, k=1, 9)]
      call stable_order(keys, order, stat)
      call check(error, stat == 0 .and. all(order == [(10 - k, k=1, 9)]), "reversed keys")
   end subroutine test_small

end module test_fd_sort
