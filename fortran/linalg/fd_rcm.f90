!> Reverse Cuthill-McKee ordering of the graph of a structure (nodes = DOFs, edges = springs,
!> devices and dashpots between two DOFs; edges to the table, node 0, are ignored), and the
!> bandwidth of a matrix with that graph under an ordering.
!>
!> Cuthill-McKee numbers the nodes by a breadth-first search from a pseudo-peripheral node
!> (found by the George-Liu iteration), visiting the neighbours of each node by increasing
!> degree; reversing that order (George) gives the same bandwidth and a smaller profile.
!> Each connected component is ordered on its own, seeded by an unnumbered node of least
!> degree (then least number). A chain, however numbered, comes back as a path: bandwidth 1.
!>
!> The cost is linear in nodes + edges apart from the George-Liu iteration (one breadth-first
!> search of a component per step, a few steps in practice): the adjacency lists are sorted
!> by counting, and the seeds are taken in turn from the nodes bucketed by degree, so that
!> 1e5 unconnected masses cost as little as a chain of 1e5.
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
      integer, allocatable :: start(:), adj(:), deg(:), by_degree(:), level(:), order(:)
      logical, allocatable :: done(:)
      integer :: nn, e, root, nlev, nlev2, first, last, last2, cand, head, tail, v, w, k, next

      if (n == 0) return
      call adjacency(n, edge_i, edge_j, start, adj, deg, by_degree)
      allocate (level(n), order(n), done(n))
      level = -1
      done = .false.
      nn = 0
      next = 1
      do
         ! seed of the next component: an unnumbered node of least degree, then least number
         ! (by_degree lists the nodes so; the nodes before next are all numbered)
         do while (next <= n)
            if (.not. done(by_degree(next))) exit
            next = next + 1
         end do
         if (next > n) exit
         root = by_degree(next)
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
   !> increasing degree, then node number; by_degree lists the nodes in that order. Every
   !> sort is a counting sort: linear in nodes + edges, whatever the degrees.
   pure subroutine adjacency(n, edge_i, edge_j, start, adj, deg, by_degree)
      integer, intent(in) :: n
      integer, intent(in) :: edge_i(:), edge_j(:)
      integer, allocatable, intent(out) :: start(:), adj(:), deg(:), by_degree(:)
      integer, allocatable :: fill(:), raw(:), sorted(:), bucket(:)
      integer :: e, a, b, v, k, m, x, cnt, prev

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
      allocate (raw(start(n + 1) - 1), sorted(start(n + 1) - 1))
      fill = start(1:n)
      do e = 1, size(edge_i)
         a = edge_i(e); b = edge_j(e)
         if (a <= 0 .or. b <= 0 .or. a == b) cycle
         raw(fill(a)) = b
         fill(a) = fill(a) + 1
         raw(fill(b)) = a
         fill(b) = fill(b) + 1
      end do
      ! each list by node number: the graph is symmetric, so listing x in the list of each of
      ! its neighbours, x = 1, 2, ..., gives every list again (repeats included), sorted
      call list_in_order(n, start, [(x, x=1, n)], raw, sorted, fill)
      ! drop repeated neighbours (adjacent once sorted)
      cnt = 0
      do v = 1, n
         m = cnt
         prev = 0
         do k = start(v), start(v + 1) - 1
            if (sorted(k) == prev) cycle
            prev = sorted(k)
            m = m + 1
            sorted(m) = prev
         end do
         start(v) = cnt + 1
         deg(v) = m - cnt
         cnt = m
      end do
      start(n + 1) = cnt + 1
      ! the nodes by increasing degree, then node number (a stable counting sort)
      allocate (bucket(0:maxval(deg) + 1), by_degree(n))
      bucket = 0
      do v = 1, n
         bucket(deg(v) + 1) = bucket(deg(v) + 1) + 1
      end do
      bucket(0) = 1
      do k = 1, ubound(bucket, 1)
         bucket(k) = bucket(k) + bucket(k - 1)
      end do
      do v = 1, n
         by_degree(bucket(deg(v))) = v
         bucket(deg(v)) = bucket(deg(v)) + 1
      end do
      ! each list by increasing degree, then node number: x in that order, listed in the
      ! list of each of its neighbours
      allocate (adj(cnt))
      call list_in_order(n, start, by_degree, sorted, adj, fill)
   end subroutine adjacency

   !> The adjacency lists `from` listed again into `to` (the same layout, start) with each
   !> list in the order of the nodes in `order`: every node x, in that order, is appended to
   !> the list of each of its neighbours (the graph is symmetric).
   pure subroutine list_in_order(n, start, order, from, to, fill)
      integer, intent(in) :: n
      integer, intent(in) :: start(:)            !! list x is from(start(x):start(x + 1) - 1)
      integer, intent(in) :: order(:)            !! the nodes 1..n in the lists' order
      integer, intent(in) :: from(:)             !! the lists
      integer, intent(inout) :: to(:)            !! the lists in that order
      integer, intent(inout) :: fill(:)          !! work (n)
      integer :: m, x, k, v
      fill = start(1:n)
      do m = 1, n
         x = order(m)
         do k = start(x), start(x + 1) - 1
            v = from(k)
            to(fill(v)) = x
            fill(v) = fill(v) + 1
         end do
      end do
   end subroutine list_in_order

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
