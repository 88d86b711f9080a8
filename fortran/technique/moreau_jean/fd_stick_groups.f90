!> The friction devices of a structure as edges of a graph over its nodes (node 0 = the
!> table), the groups of nodes that sticking devices join, and the impulses of the sticking
!> devices recovered from the nodal residual by elimination over a spanning forest.
!>
!> **Edges.** Devices between the same two nodes act as one: they always share their
!> relative velocity, so either all of them stick or all slide the same way, and only their
!> total impulse is determined. `edges_setup` merges them into one edge whose bound is the
!> sum of theirs (devices with P mu = 0 exert no force and are left out); a device's share
!> of its edge's impulse is its bound over the edge's, so that parallel devices reach their
!> limits together.
!>
!> **Groups.** For a set of sticking edges, `groups_build` finds the connected groups of
!> nodes by breadth-first search over those edges: the group of the table (index 0) does not
!> move relative to it; every other group gets the index 1..nr in the order of its first node
!> in a given node order (the RCM order of the structure: a shear building's groups are
!> intervals of its storeys, numbered in order, so that its reduced system is again a
!> chain). The search leaves a spanning forest: each node's parent edge, and the edges that
!> close a loop (a redundant sticking device, `tree` false).
!>
!> **Impulses of sticking edges.** Given the nodal residual rho = B_S lambda_S (what the
!> sticking edges must carry at every node), `recover_impulses` solves for lambda_S by
!> eliminating leaves first: a node's parent edge carries the sum of rho over the node's
!> subtree. On a forest the solution is unique; a loop edge is given no impulse (one
!> solution among many). The sum of rho over a whole group not containing the table is
!> zero when rho is consistent; its size relative to the group's scale is returned.
!>
!> Only `edges_setup` allocates.
module fd_stick_groups
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, allocation_error
   implicit none
   private

   public :: edge_set, edges_setup, groups_build, recover_impulses, expand, restrict, add_edge, edge_relative

   !> The devices as edges, their incidence, and the groups of the last groups_build.
   type :: edge_set
      integer :: n = 0                     !! nodes 1..n (0: the table)
      integer :: ne = 0                    !! edges
      integer, allocatable :: ei(:)        !! first node of each edge (1..n), b_e = e_ei - e_ej
      integer, allocatable :: ej(:)        !! second node of each edge (0..n)
      real(dp), allocatable :: pmu(:)      !! sum of P mu of the edge's devices [N]
      integer, allocatable :: dev_edge(:)  !! edge of each device (0: P mu = 0, no edge)
      integer, allocatable :: dev_sign(:)  !! +1 when the device is oriented as its edge, -1 else
      real(dp), allocatable :: dev_share(:) !! the device's P mu over its edge's
      integer, allocatable :: start(:)     !! (0:n+1) incidence: edges of node x are inc(start(x):start(x+1)-1)
      integer, allocatable :: inc(:)       !! incident edges, each edge twice
      ! ---- the groups of the last groups_build
      integer :: nr = 0                    !! moving groups
      integer :: nord = 0                  !! nodes in order(:)
      integer, allocatable :: grp(:)       !! (0:n) group of each node, 0 = with the table
      integer, allocatable :: order(:)     !! (n+1) nodes in search order, roots first in each group
      integer, allocatable :: parent(:)    !! (0:n) edge to the parent node, 0 for a root
      logical, allocatable :: tree(:)      !! (ne) a sticking edge of the spanning forest
      logical, allocatable :: loops(:)     !! (0:nr) the group holds a loop edge (redundant)
   end type edge_set

contains

   !> Edges from the devices: one per pair of nodes joined by devices with P mu > 0.
   subroutine edges_setup(es, n, dev_i, dev_j, pmu, error)
      type(edge_set), intent(out) :: es             !! the edges
      integer, intent(in) :: n                      !! number of DOFs (nodes 1..n)
      integer, intent(in) :: dev_i(:)               !! first node of each device (1..n)
      integer, intent(in) :: dev_j(:)               !! second node of each device (0..n)
      real(dp), intent(in) :: pmu(:)                !! P mu of each device [N], >= 0
      type(error_type), allocatable, intent(out) :: error !! a device on one node, out of range
      integer, allocatable :: head(:), next(:), fill(:)
      integer :: nd, d, a, b, e, lo, hi, stat

      nd = size(dev_i)
      es%n = n
      allocate (es%dev_edge(nd), es%dev_sign(nd), es%dev_share(nd), es%ei(nd), es%ej(nd), es%pmu(nd), &
                head(0:n), next(nd), stat=stat)
      call allocation_error(error, stat, "the friction edges of n_dof = "//trim(fmt_int(n))//" DOFs")
      if (stat /= 0) return
      es%dev_edge = 0
      es%dev_sign = 1
      es%dev_share = 0.0_dp
      head = 0
      es%ne = 0
      do d = 1, nd
         a = dev_i(d)
         b = dev_j(d)
         if (a < 1 .or. a > n .or. b < 0 .or. b > n .or. a == b) then
            call fatal_error(error, "edges_setup: device "//trim(fmt_int(d))//" joins nodes "// &
                             trim(fmt_int(a))//" and "//trim(fmt_int(b))//" (1.."//trim(fmt_int(n))// &
                             " and 0.."//trim(fmt_int(n))//", distinct)")
            return
         end if
         if (.not. (pmu(d) > 0.0_dp)) cycle
         lo = min(a, b)
         hi = max(a, b)
         ! an edge between the same nodes already?
         e = head(lo)
         do while (e /= 0)
            if (min(es%ei(e), es%ej(e)) == lo .and. max(es%ei(e), es%ej(e)) == hi) exit
            e = next(e)
         end do
         if (e == 0) then
            es%ne = es%ne + 1
            e = es%ne
            es%ei(e) = a
            es%ej(e) = b
            es%pmu(e) = 0.0_dp
            next(e) = head(lo)
            head(lo) = e
         end if
         es%dev_edge(d) = e
         es%dev_sign(d) = merge(1, -1, es%ei(e) == a)
         es%pmu(e) = es%pmu(e) + pmu(d)
      end do
      do d = 1, nd
         if (es%dev_edge(d) > 0) es%dev_share(d) = pmu(d)/es%pmu(es%dev_edge(d))
      end do
      es%ei = es%ei(1:es%ne)
      es%ej = es%ej(1:es%ne)
      es%pmu = es%pmu(1:es%ne)
      ! incidence over nodes 0..n
      allocate (es%start(0:n + 1), fill(0:n), es%inc(2*es%ne), stat=stat)
      call allocation_error(error, stat, "the friction edges of n_dof = "//trim(fmt_int(n))//" DOFs")
      if (stat /= 0) return
      es%start = 0
      do e = 1, es%ne
         es%start(es%ei(e)) = es%start(es%ei(e)) + 1
         es%start(es%ej(e)) = es%start(es%ej(e)) + 1
      end do
      a = 1
      do d = 0, n
         b = es%start(d)
         es%start(d) = a
         a = a + b
      end do
      es%start(n + 1) = a
      fill = es%start(0:n)
      do e = 1, es%ne
         es%inc(fill(es%ei(e))) = e
         fill(es%ei(e)) = fill(es%ei(e)) + 1
         es%inc(fill(es%ej(e))) = e
         fill(es%ej(e)) = fill(es%ej(e)) + 1
      end do
      allocate (es%grp(0:n), es%order(n + 1), es%parent(0:n), es%tree(es%ne), es%loops(0:n), stat=stat)
      call allocation_error(error, stat, "the friction edges of n_dof = "//trim(fmt_int(n))//" DOFs")
      if (stat /= 0) return
      es%grp = 0
      es%order = 0
      es%parent = 0
      es%tree = .false.
      es%loops = .false.
   end subroutine edges_setup

   !> Groups of the nodes joined by the sticking edges, numbered 1..nr by their first node
   !> in node_order (0: the table's group), with a spanning forest for recover_impulses.
   pure subroutine groups_build(es, stuck, node_order)
      type(edge_set), intent(inout) :: es      !! the edges; grp, nr, order, parent, tree, loops set
      logical, intent(in) :: stuck(:)          !! (ne) sticking edges
      integer, intent(in) :: node_order(:)     !! (n) the nodes in the order that numbers groups
      integer :: k, x

      es%grp = -1
      es%parent = 0
      es%tree = .false.
      es%loops = .false.
      es%nord = 0
      es%nr = 0
      call search(es, stuck, 0, 0)
      do k = 1, es%n
         x = node_order(k)
         if (es%grp(x) >= 0) cycle
         es%nr = es%nr + 1
         call search(es, stuck, x, es%nr)
      end do
   end subroutine groups_build

   !> Breadth-first search over the sticking edges from x0, labelling its group.
   pure subroutine search(es, stuck, x0, label)
      type(edge_set), intent(inout) :: es
      logical, intent(in) :: stuck(:)
      integer, intent(in) :: x0, label
      integer :: head, y, q, e, z

      es%grp(x0) = label
      es%nord = es%nord + 1
      es%order(es%nord) = x0
      head = es%nord
      do while (head <= es%nord)
         y = es%order(head)
         head = head + 1
         do q = es%start(y), es%start(y + 1) - 1
            e = es%inc(q)
            if (.not. stuck(e)) cycle
            z = es%ei(e) + es%ej(e) - y
            if (es%grp(z) < 0) then
               es%grp(z) = label
               es%parent(z) = e
               es%tree(e) = .true.
               es%nord = es%nord + 1
               es%order(es%nord) = z
            else if (.not. es%tree(e)) then
               es%loops(label) = .true.
            end if
         end do
      end do
   end subroutine search

   !> Impulses of the sticking edges from the nodal residual rho = B_S lambda_S, leaves
   !> first over the forest of groups_build; loop edges get 0. rho and scale (the size of the
   !> terms rho was computed from, for the tolerances) are overwritten by their subtree sums.
   pure subroutine recover_impulses(es, stuck, rho, scale, lam, lam_scale, mismatch)
      type(edge_set), intent(in) :: es         !! edges and forest (groups_build)
      logical, intent(in) :: stuck(:)          !! (ne) the sticking edges of groups_build
      real(dp), intent(inout) :: rho(0:)       !! nodal residual; on exit the subtree sums
      real(dp), intent(inout) :: scale(0:)     !! size of rho's terms (>= 0); on exit subtree sums
      real(dp), intent(inout) :: lam(:)        !! (ne) impulses: set for the sticking edges
      real(dp), intent(inout) :: lam_scale(:)  !! (ne) size of the terms of each lambda (for tolerances)
      real(dp), intent(out) :: mismatch        !! max over moving groups |sum rho| / sum scale
      integer :: k, x, e, y

      do e = 1, es%ne
         if (stuck(e) .and. .not. es%tree(e)) then
            lam(e) = 0.0_dp
            lam_scale(e) = 0.0_dp
         end if
      end do
      mismatch = 0.0_dp
      do k = es%nord, 1, -1
         x = es%order(k)
         e = es%parent(x)
         if (e == 0) then
            if (x /= 0 .and. scale(x) > 0.0_dp) mismatch = max(mismatch, abs(rho(x))/scale(x))
            cycle
         end if
         ! the node's equation: b_e(x) lambda_e = rho_x (its subtree's sum)
         if (es%ei(e) == x) then
            lam(e) = rho(x)
            y = es%ej(e)
         else
            lam(e) = -rho(x)
            y = es%ei(e)
         end if
         lam_scale(e) = scale(x)
         rho(y) = rho(y) + rho(x)
         scale(y) = scale(y) + scale(x)
      end do
   end subroutine recover_impulses

   !> v(i) = q(grp(i)) for a moving group, 0 for the table's: u = T q.
   pure subroutine expand(es, q, v)
      type(edge_set), intent(in) :: es   !! groups (groups_build)
      real(dp), intent(in) :: q(:)       !! reduced vector (nr)
      real(dp), intent(out) :: v(:)      !! nodal vector (n)
      integer :: i

      do i = 1, es%n
         if (es%grp(i) > 0) then
            v(i) = q(es%grp(i))
         else
            v(i) = 0.0_dp
         end if
      end do
   end subroutine expand

   !> q(g) = sum of f over the nodes of group g: q = T' f.
   pure subroutine restrict(es, f, q)
      type(edge_set), intent(in) :: es   !! groups (groups_build)
      real(dp), intent(in) :: f(:)       !! nodal vector (n)
      real(dp), intent(out) :: q(:)      !! reduced vector (nr)
      integer :: i

      q(1:es%nr) = 0.0_dp
      do i = 1, es%n
         if (es%grp(i) > 0) q(es%grp(i)) = q(es%grp(i)) + f(i)
      end do
   end subroutine restrict

   !> y = y + alpha b_e.
   pure subroutine add_edge(es, e, alpha, y)
      type(edge_set), intent(in) :: es   !! edges
      integer, intent(in) :: e           !! edge
      real(dp), intent(in) :: alpha      !! factor
      real(dp), intent(inout) :: y(:)    !! nodal vector (n)

      y(es%ei(e)) = y(es%ei(e)) + alpha
      if (es%ej(e) > 0) y(es%ej(e)) = y(es%ej(e)) - alpha
   end subroutine add_edge

   !> b_e' y.
   pure real(dp) function edge_relative(es, e, y) result(rel)
      type(edge_set), intent(in) :: es   !! edges
      integer, intent(in) :: e           !! edge
      real(dp), intent(in) :: y(:)       !! nodal vector (n)

      rel = y(es%ei(e))
      if (es%ej(e) > 0) rel = rel - y(es%ej(e))
   end function edge_relative

end module fd_stick_groups
