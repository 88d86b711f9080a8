!> Reverse Cuthill-McKee ordering of the graph of a structure (nodes = DOFs, edges = springs,
!> devices and dashpots between two DOFs; edges to the table, node 0, are ignored), and the
!> bandwidth of a matrix with that graph under an ordering.
!>
!> Cuthill-McKee numbers the nodes by a breadth-first search from a pseudo-peripheral node
!> (found by the George-Liu iteration), visiting the neighbours of each node by increasing
!> degree; reversing that order (George) gives the same bandwidth and a smaller profile.
!> Each connected component is ordered on its own. A chain, however numbered, comes back as
!> a path: bandwidth 1.
module fd_rcm
   implicit none
   private

   public :: rcm_order, graph_bandwidth

contains

   !> Reverse Cuthill-McKee ordering: perm(k) is the node numbered k in the new ordering.
   pure subroutine rcm_order(n, edge_i, edge_j, perm)
      integer, intent(in) :: n              !! number of nodes (1..n)
      integer, intent(in) :: edge_i(:)      !! first node of each edge (0 = table, ignored)
      integer, intent(in) :: edge_j(:)      !! second node of each edge (0 = table, ignored)
      integer, intent(out) :: perm(:)       !! new -> old, size n
      integer, allocatable :: start(:), adj(:), deg(:), level(:), order(:)
      logical, allocatable :: done(:)
      integer :: nn, i, e, root, nlev, nlev2, first, last, last2, cand, head, tail, v, w, k

      if (n == 0) return
      call adjacency(n, edge_i, edge_j, start, adj, deg)
      allocate (level(n), order(n), done(n))
      level = -1
      done = .false.
      nn = 0
      do
         ! seed of the next component: an unnumbered node of least degree
         root = 0
         do i = 1, n
            if (done(i)) cycle
            if (root == 0) then
               root = i
            else if (deg(i) < deg(root)) then
               root = i
            end if
         end do
         if (root == 0) exit
         ! George-Liu: move to a node of least degree in the last level while the
         ! eccentricity grows
         call levels(root, nn, start, adj, done, level, order, first, last, nlev)
         do
            cand = order(first)
            do k = first, last
               if (deg(order(k)) < deg(cand)) cand = order(k)
            end do
            call clear(order(nn + 1:last), level)
            call levels(cand, nn, start, adj, done, level, order, first, last2, nlev2)
            if (nlev2 > nlev) then
               root = cand
               nlev = nlev2
               last = last2
            else
               call clear(order(nn + 1:last2), level)
               exit
            end if
         end do
         call clear(order(nn + 1:last), level)
         ! Cuthill-McKee from root: neighbours by increasing degree (adj is sorted so)
         head = nn + 1
         tail = nn + 1
         order(tail) = root
         done(root) = .true.
         do while (head <= tail)
            v = order(head)
            head = head + 1
            do e = start(v), start(v + 1) - 1
               w = adj(e)
               if (done(w)) cycle
               done(w) = .true.
               tail = tail + 1
               order(tail) = w
            end do
         end do
         nn = tail
      end do
      do k = 1, n
         perm(k) = order(n + 1 - k)
      end do

   end subroutine rcm_order

   !> Breadth-first level structure from r over the nodes not yet numbered, written to
   !> order(nn+1:last); the last level is order(first:last), nlev the number of levels.
   pure subroutine levels(r, nn, start, adj, done, level, order, first, last, nlev)
      integer, intent(in) :: r, nn
      integer, intent(in) :: start(:), adj(:)
      logical, intent(in) :: done(:)
      integer, intent(inout) :: level(:), order(:)
      integer, intent(out) :: first, last, nlev
      integer :: h, x, y, q

      last = nn + 1
      order(last) = r
      level(r) = 1
      h = nn + 1
      do while (h <= last)
         x = order(h)
         h = h + 1
         do q = start(x), start(x + 1) - 1
            y = adj(q)
            if (level(y) >= 0 .or. done(y)) cycle
            level(y) = level(x) + 1
            last = last + 1
            order(last) = y
         end do
      end do
      nlev = level(order(last))
      first = last
      do while (first > nn + 1)
         if (level(order(first - 1)) /= nlev) exit
         first = first - 1
      end do
   end subroutine levels

   !> Reset the levels of the given nodes.
   pure subroutine clear(nodes, level)
      integer, intent(in) :: nodes(:)
      integer, intent(inout) :: level(:)

      level(nodes) = -1
   end subroutine clear

   !> Adjacency lists (compressed, without self-loops and repeated edges), each sorted by
   !> increasing degree, then node number.
   pure subroutine adjacency(n, edge_i, edge_j, start, adj, deg)
      integer, intent(in) :: n
      integer, intent(in) :: edge_i(:), edge_j(:)
      integer, allocatable, intent(out) :: start(:), adj(:), deg(:)
      integer, allocatable :: fill(:), raw(:)
      integer :: e, a, b, v, k, m, x, cnt

      allocate (start(n + 1), fill(n), deg(n))
      fill = 0
      do e = 1, size(edge_i)
         a = edge_i(e); b = edge_j(e)
         if (a <= 0 .or. b <= 0 .or. a == b) cycle
         fill(a) = fill(a) + 1
         fill(b) = fill(b) + 1
      end do
      start(1) = 1
      do v = 1, n
         start(v + 1) = start(v) + fill(v)
      end do
      allocate (raw(start(n + 1) - 1))
      fill = start(1:n)
      do e = 1, size(edge_i)
         a = edge_i(e); b = edge_j(e)
         if (a <= 0 .or. b <= 0 .or. a == b) cycle
         raw(fill(a)) = b
         fill(a) = fill(a) + 1
         raw(fill(b)) = a
         fill(b) = fill(b) + 1
      end do
      ! drop repeated neighbours (sort each list by node number first)
      cnt = 0
      do v = 1, n
         call insertion_sort(raw(start(v):start(v + 1) - 1))
         m = cnt
         do k = start(v), start(v + 1) - 1
            if (k > start(v)) then
               if (raw(k) == raw(k - 1)) cycle
            end if
            m = m + 1
            raw(m) = raw(k)
         end do
         start(v) = cnt + 1
         deg(v) = m - cnt
         cnt = m
      end do
      start(n + 1) = cnt + 1
      adj = raw(1:cnt)
      ! neighbours by increasing degree (stable: equal degrees keep node order)
      do v = 1, n
         do k = start(v) + 1, start(v + 1) - 1
            x = adj(k)
            m = k - 1
            do while (m >= start(v))
               if (deg(adj(m)) <= deg(x)) exit
               adj(m + 1) = adj(m)
               m = m - 1
            end do
            adj(m + 1) = x
         end do
      end do
   end subroutine adjacency

   pure subroutine insertion_sort(a)
      integer, intent(inout) :: a(:)
      integer :: k, m, x

      do k = 2, size(a)
         x = a(k)
         m = k - 1
         do while (m >= 1)
            if (a(m) <= x) exit
            a(m + 1) = a(m)
            m = m - 1
         end do
         a(m + 1) = x
      end do
   end subroutine insertion_sort

   !> Half-bandwidth max |inv(a) - inv(b)| over the edges between two nodes (0 without any),
   !> where inv(old) is the new number of a node.
   pure integer function graph_bandwidth(edge_i, edge_j, inv) result(kb)
      integer, intent(in) :: edge_i(:)   !! first node of each edge (0 = table, ignored)
      integer, intent(in) :: edge_j(:)   !! second node of each edge (0 = table, ignored)
      integer, intent(in) :: inv(:)      !! old -> new numbering
      integer :: e

      kb = 0
      do e = 1, size(edge_i)
         if (edge_i(e) <= 0 .or. edge_j(e) <= 0) cycle
         kb = max(kb, abs(inv(edge_i(e)) - inv(edge_j(e))))
      end do
   end function graph_bandwidth

end module fd_rcm
