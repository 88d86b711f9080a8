!> Unit tests of the devices as edges, the groups of sticking devices and the recovery of
!> their impulses (fd_stick_groups): parallel devices merged with their orientation and
!> shares, groups of a chain as numbered intervals, impulses on a random forest recovered
!> exactly from B lambda, a loop of devices flagged and still consistent.
module test_fd_stick_groups
   use testdrive, only: new_unittest, unittest_type, error_type, check, test_failed
   use fd_kinds, only: dp
   use fd_error, only: fd_error_type => error_type
   use fd_stick_groups, only: edge_set, edges_setup, groups_build, recover_impulses, expand, restrict, &
                              add_edge, edge_relative
   use test_fd_helpers, only: check_close
   implicit none
   private

   public :: collect_stick_groups

contains

   subroutine collect_stick_groups(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("parallel devices are one edge", test_parallel), &
                  new_unittest("chain: groups are numbered intervals", test_chain_groups), &
                  new_unittest("impulses of a random forest", test_random_forest), &
                  new_unittest("loop flagged, impulses consistent", test_loop), &
                  new_unittest("restrict and expand are T' and T", test_restrict_expand), &
                  new_unittest("device on one node is an error", test_bad_device) &
                  ]
   end subroutine collect_stick_groups

   !> Devices 1: 1-2, 2: 2-1, 3: 1-table, 4: 1-2 again, 5: P mu = 0.
   subroutine test_parallel(error)
      type(error_type), allocatable, intent(out) :: error
      type(edge_set) :: es
      type(fd_error_type), allocatable :: err

      call edges_setup(es, 2, [1, 2, 1, 1, 2], [2, 1, 0, 2, 0], [1.0_dp, 2.0_dp, 3.0_dp, 5.0_dp, 0.0_dp], err)
      call check(error, .not. allocated(err), "set-up")
      if (allocated(error)) return
      call check(error, es%ne, 2, "edges")
      if (allocated(error)) return
      call check(error, all(es%dev_edge == [1, 1, 2, 1, 0]), "edge of each device")
      if (allocated(error)) return
      call check(error, all(es%dev_sign == [1, -1, 1, 1, 1]), "orientation of each device")
      if (allocated(error)) return
      call check_close(error, es%pmu(1), 8.0_dp, 1.0e-15_dp, "P mu of the parallel edge")
      if (allocated(error)) return
      call check_close(error, es%dev_share(2), 0.25_dp, 1.0e-15_dp, "share of device 2")
      if (allocated(error)) return
      call check_close(error, es%dev_share(3), 1.0_dp, 1.0e-15_dp, "share of device 3")
      if (allocated(error)) return
      call check(error, es%dev_share(5) == 0.0_dp, "a device without force has no share")
   end subroutine test_parallel

   !> Chain of 6 nodes, device d between nodes d and d - 1 (device 1 to the table).
   subroutine test_chain_groups(error)
      type(error_type), allocatable, intent(out) :: error
      type(edge_set) :: es
      type(fd_error_type), allocatable :: err
      integer :: d, order(6)

      call edges_setup(es, 6, [(d, d=1, 6)], [(d - 1, d=1, 6)], [(1.0_dp, d=1, 6)], err)
      call check(error, .not. allocated(err), "set-up")
      if (allocated(error)) return
      ! devices 1 and 2 stick: nodes 1, 2 with the table; 4 sticks: nodes 3, 4 one group; 5, 6 free
      order = [(d, d=1, 6)]
      call groups_build(es, [.true., .true., .false., .true., .false., .false.], order)
      call check(error, es%nr, 3, "moving groups")
      if (allocated(error)) return
      call check(error, all(es%grp(1:6) == [0, 0, 1, 1, 2, 3]), "groups numbered bottom up")
      if (allocated(error)) return
      ! the same in the reverse node order: numbered top down, still intervals
      order = [(7 - d, d=1, 6)]
      call groups_build(es, [.true., .true., .false., .true., .false., .false.], order)
      call check(error, all(es%grp(1:6) == [0, 0, 3, 3, 2, 1]), "groups numbered top down")
      if (allocated(error)) return
      call check(error, .not. any(es%loops(0:es%nr)), "a chain has no loop")
   end subroutine test_chain_groups

   !> A random forest of sticking edges over 40 nodes (some rooted at the table): lambda
   !> recovered from rho = B lambda to round-off, the moving groups' sums zero.
   subroutine test_random_forest(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 40
      type(edge_set) :: es
      type(fd_error_type), allocatable :: err
      integer :: ei(n), ej(n), order(n), i, k
      real(dp) :: lam(n), got(n), lsc(n), rho(0:n), sc(0:n), y(n), mm
      logical :: stuck(n)
      integer(8) :: s

      s = 7
      do i = 1, n
         ! node i hangs from a random earlier node or the table
         ei(i) = i
         ej(i) = int(mod(next(s), int(i, 8)))
         lam(i) = real(mod(next(s), 2001_8) - 1000, dp)/7.0_dp
         stuck(i) = mod(next(s), 5_8) /= 0
      end do
      call edges_setup(es, n, ei, ej, [(1.0_dp, i=1, n)], err)
      call check(error, .not. allocated(err), "set-up")
      if (allocated(error)) return
      order = [(i, i=1, n)]
      call groups_build(es, stuck, order)
      call check(error, .not. any(es%loops(0:es%nr)), "a forest has no loop")
      if (allocated(error)) return
      y = 0.0_dp
      do k = 1, n
         if (stuck(k)) call add_edge(es, k, lam(k), y)
      end do
      rho(0) = 0.0_dp
      rho(1:n) = y
      sc(0) = 0.0_dp
      sc(1:n) = abs(y)
      got = 0.0_dp
      call recover_impulses(es, stuck, rho, sc, got, lsc, mm)
      call check(error, mm <= 1.0e-15_dp, "the moving groups' residuals sum to zero")
      if (allocated(error)) return
      do k = 1, n
         if (.not. stuck(k)) cycle
         call check_close(error, got(k), lam(k), 1.0e-12_dp*maxval(abs(lam)), "impulse of a sticking edge", &
                          absolute=.true.)
         if (allocated(error)) return
      end do
   contains
      integer(8) function next(x)
         integer(8), intent(inout) :: x
         x = mod(16807_8*x, 2147483647_8)
         next = x
      end function next
   end subroutine test_random_forest

   !> Nodes 1, 2 and the table joined by three sticking devices (1-0, 2-1, 2-0): a loop; the
   !> impulses found (one redundant edge given none) still reproduce rho = B lambda.
   subroutine test_loop(error)
      type(error_type), allocatable, intent(out) :: error
      type(edge_set) :: es
      type(fd_error_type), allocatable :: err
      real(dp) :: rho(0:2), sc(0:2), got(3), lsc(3), y(2), mm
      integer :: k

      call edges_setup(es, 2, [1, 2, 2], [0, 1, 0], [1.0_dp, 1.0_dp, 1.0_dp], err)
      call check(error, .not. allocated(err), "set-up")
      if (allocated(error)) return
      call groups_build(es, [.true., .true., .true.], [1, 2])
      call check(error, es%loops(0), "the table's group has a loop")
      if (allocated(error)) return
      call check(error, es%nr, 0, "no moving group")
      if (allocated(error)) return
      rho = [0.0_dp, 3.0_dp, -5.0_dp]
      sc = abs(rho)
      call recover_impulses(es, [.true., .true., .true.], rho, sc, got, lsc, mm)
      y = 0.0_dp
      do k = 1, 3
         call add_edge(es, k, got(k), y)
      end do
      call check_close(error, y(1), 3.0_dp, 1.0e-15_dp, "B lambda at node 1")
      if (allocated(error)) return
      call check_close(error, y(2), -5.0_dp, 1.0e-15_dp, "B lambda at node 2")
   end subroutine test_loop

   subroutine test_restrict_expand(error)
      type(error_type), allocatable, intent(out) :: error
      type(edge_set) :: es
      type(fd_error_type), allocatable :: err
      real(dp) :: f(5), q(5), v(5)
      integer :: d

      call edges_setup(es, 5, [(d, d=1, 5)], [(d - 1, d=1, 5)], [(2.0_dp, d=1, 5)], err)
      call check(error, .not. allocated(err), "set-up")
      if (allocated(error)) return
      call groups_build(es, [.false., .true., .false., .true., .true.], [(d, d=1, 5)])
      ! groups {1, 2}, {3, 4, 5}
      f = [1.0_dp, 2.0_dp, 3.0_dp, 4.0_dp, 5.0_dp]
      call restrict(es, f, q)
      call check(error, es%nr == 2 .and. q(1) == 3.0_dp .and. q(2) == 12.0_dp, "T' f sums each group")
      if (allocated(error)) return
      call expand(es, [7.0_dp, -1.0_dp], v)
      call check(error, all(v == [7.0_dp, 7.0_dp, -1.0_dp, -1.0_dp, -1.0_dp]), "T q copies each group")
      if (allocated(error)) return
      call check(error, edge_relative(es, 2, v) == 0.0_dp .and. edge_relative(es, 3, v) == -8.0_dp, &
                 "relative velocity: zero inside a group")
   end subroutine test_restrict_expand

   subroutine test_bad_device(error)
      type(error_type), allocatable, intent(out) :: error
      type(edge_set) :: es
      type(fd_error_type), allocatable :: err

      call edges_setup(es, 3, [1, 2], [0, 2], [1.0_dp, 1.0_dp], err)
      call check(error, allocated(err), "a device joining node 2 to itself is refused")
      if (allocated(error)) return
      call check(error, index(err%message, "device 2") > 0, err%message)
   end subroutine test_bad_device

end module test_fd_stick_groups
