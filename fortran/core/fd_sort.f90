!> A stable order of items by a comparison their owner gives: a type that extends sort_keys
!> and says whether one item goes before another (before). One bottom-up merge sort, linear-
!> logarithmic in the items, for every reader that looks for repeats by sorting (the deck's
!> variables, a Matrix Market file's positions).
module fd_sort
   implicit none
   private

   public :: sort_keys, stable_order

   !> What items are sorted by: before(a, b) for two of them (their numbers).
   type, abstract :: sort_keys
   contains
      procedure(before_item), deferred :: before
   end type sort_keys

   abstract interface
      !> Whether item a goes before item b (neither: they keep their order).
      pure logical function before_item(keys, a, b)
         import :: sort_keys
         class(sort_keys), intent(in) :: keys   !! the items' keys
         integer, intent(in) :: a, b            !! two items
      end function before_item
   end interface

contains

   !> order (item numbers) in the order of keys; items that neither goes before keep their
   !> order in it (stable). stat: 0, or not enough memory (order as it was).
   pure subroutine stable_order(keys, order, stat)
      class(sort_keys), intent(in) :: keys     !! the items' keys
      integer, intent(inout) :: order(:)       !! item numbers, sorted
      integer, intent(out) :: stat             !! 0, or the allocation's status
      integer, allocatable :: tmp(:)
      integer :: n, width, lo, mid, hi, a, b, c

      n = size(order)
      allocate (tmp(n), stat=stat)
      if (stat /= 0) return
      width = 1
      do while (width < n)
         lo = 1
         do while (lo <= n)
            ! merge order(lo:mid-1) and order(mid:hi-1), the left one first among equals
            mid = min(lo + width, n + 1)
            hi = min(lo + 2*width, n + 1)
            a = lo
            b = mid
            do c = lo, hi - 1
               if (b >= hi) then
                  tmp(c) = order(a)
                  a = a + 1
               else if (a >= mid) then
                  tmp(c) = order(b)
                  b = b + 1
               else if (keys%before(order(b), order(a))) then
                  tmp(c) = order(b)
                  b = b + 1
               else
                  tmp(c) = order(a)
                  a = a + 1
               end if
            end do
            lo = hi
         end do
         order = tmp
         width = 2*width
      end do
   end subroutine stable_order

end module fd_sort
