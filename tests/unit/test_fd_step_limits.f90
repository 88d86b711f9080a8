!> Unit tests of the step limits (fd_step_limits): the levels of nested refinement are the
!> prime factors of n2, smallest first, whose product is n2 (so that the last level is dt2
!> exactly), and the halving levels down to dt_min.
module test_fd_step_limits
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_step_limits, only: nested_splits, max_nested, halving_levels
   implicit none
   private

   public :: collect_step_limits

contains

   subroutine collect_step_limits(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("nested levels of known n2", test_known), &
                  new_unittest("nested levels multiply to n2", test_product), &
                  new_unittest("halving levels", test_halving) &
                  ]
   end subroutine collect_step_limits

   subroutine test_known(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: splits(max_nested), levels

      call nested_splits(50, splits, levels)
      call check(error, levels == 3 .and. all(splits(1:3) == [2, 5, 5]), "n2 = 50: dt1/2, dt1/10, dt2")
      if (allocated(error)) return
      call nested_splits(1, splits, levels)
      call check(error, levels == 0, "n2 = 1: no level")
      if (allocated(error)) return
      call nested_splits(53, splits, levels)
      call check(error, levels == 1 .and. splits(1) == 53, "a prime n2: one level, the paper's refinement")
      if (allocated(error)) return
      call nested_splits(2**20, splits, levels)
      call check(error, levels == 20 .and. all(splits == 2), "n2 = 2**20: twenty halvings")
      if (allocated(error)) return
      call nested_splits(2*1048573, splits, levels)   ! 1048573 is prime
      call check(error, levels == 2 .and. splits(1) == 2 .and. splits(2) == 1048573, "a large prime factor")
   end subroutine test_known

   subroutine test_product(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: splits(max_nested), levels, n2, k, d

      do n2 = 1, 5000
         call nested_splits(n2, splits, levels)
         call check(error, product(splits(1:levels)) == n2, "the levels multiply to n2")
         if (allocated(error)) return
         do k = 1, levels
            ! each split is prime and not smaller than the one before
            do d = 2, int(sqrt(real(splits(k), dp)))
               call check(error, mod(splits(k), d) /= 0, "a split is prime")
               if (allocated(error)) return
            end do
         end do
         do k = 2, levels
            call check(error, splits(k) >= splits(k - 1), "smallest first")
            if (allocated(error)) return
         end do
      end do
   end subroutine test_product

   subroutine test_halving(error)
      type(error_type), allocatable, intent(out) :: error

      call check(error, halving_levels(1.0e-3_dp, 1.0e-3_dp/2**10) == 10, "dt2 / 2**10: ten halvings")
      if (allocated(error)) return
      call check(error, halving_levels(1.0e-3_dp, 1.0e-3_dp) == 0, "dt_min = dt2: none")
      if (allocated(error)) return
      call check(error, halving_levels(1.0_dp, 1.0e-300_dp) == 30, "at most 30")
   end subroutine test_halving

end module test_fd_step_limits
