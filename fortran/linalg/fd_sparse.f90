!> The effective stiffness of fd_banded, K^ = K + c1 C + c0 M + sum_d kd_d b_d b_d', stored
!> sparse and factored by CHOLMOD (fd_cholmod.c: a fill-reducing ordering, supernodal or
!> simplicial Cholesky; its LGPL modules only) for structures whose band after reverse
!> Cuthill-McKee ordering is wide (docs/theory.md, section 10.7).
!>
!> The pattern of K^ (springs, K_x, dashpots, every pair of a device's terms, the diagonal) is
!> analysed once; K and C are kept as sparse upper triangles for the products K x and C x.
!> When devices change phase the factor A0 of K^ at its last factorization is kept and the
!> change sum_d (kd_d - kd0_d) b_d b_d' over the changed devices S is taken by the Woodbury
!> identity (a capacitance matrix of |S| x |S|, W = A0^-1 B_S kept by column); when S would
!> exceed max_changed devices, K^ is factored again with the current kd (same analysis).
!> After sparse_setup and the first factorization nothing allocates.
module fd_sparse
   use, intrinsic :: iso_c_binding, only: c_int, c_double, c_ptr, c_null_ptr, c_associated, c_long
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, stat_no_memory
   use fd_lapack, only: dgetrf, dgetrs  ! the capacitance matrix's LU (not positive definite)
   use fd_rcm, only: rcm_order, graph_bandwidth
   implicit none
   private

   public :: sparse_system, sparse_available, sparse_setup, sparse_factor, sparse_update_devices, sparse_solve
   public :: sparse_k_matvec, sparse_c_matvec, sparse_kc_matvec, sparse_free, sparse_band, sparse_factor_entries
   public :: sparse_solve_many, sparse_factor_bytes, sparse_nonzeros

   integer(c_int), parameter :: chol_ok = 0, chol_unavailable = 1, chol_no_memory = 2, chol_not_posdef = 3

   !> Most devices whose stiffness may differ from the factor's before K^ is factored again.
   integer, parameter :: changed_cap = 64

   interface
      integer(c_int) function fd_chol_available() bind(c)
         import :: c_int
      end function fd_chol_available
      integer(c_int) function fd_chol_create(n, colptr, rowind, nrhs_max, handle, lnz, flops) bind(c)
         import :: c_int, c_ptr, c_double
         integer(c_int), value :: n, nrhs_max
         integer(c_int), intent(in) :: colptr(*), rowind(*)
         type(c_ptr), intent(out) :: handle
         real(c_double), intent(out) :: lnz, flops
      end function fd_chol_create
      integer(c_int) function fd_chol_factor(handle, x, column) bind(c)
         import :: c_int, c_ptr, c_double
         type(c_ptr), value :: handle
         real(c_double), intent(in) :: x(*)
         integer(c_int), intent(out) :: column
      end function fd_chol_factor
      integer(c_int) function fd_chol_solve(handle, nrhs, b) bind(c)
         import :: c_int, c_ptr, c_double
         type(c_ptr), value :: handle
         integer(c_int), value :: nrhs
         real(c_double), intent(inout) :: b(*)
      end function fd_chol_solve
      real(c_double) function fd_chol_factor_bytes(handle) bind(c)
         import :: c_double, c_ptr
         type(c_ptr), value :: handle
      end function fd_chol_factor_bytes
      subroutine fd_chol_free(handle) bind(c)
         import :: c_ptr
         type(c_ptr), value :: handle
      end subroutine fd_chol_free
   end interface

   !> The system: pattern, K and C, the CHOLMOD factor and the Woodbury terms of the changes.
   type :: sparse_system
      integer :: n = 0, nd = 0
      type(c_ptr), private :: h = c_null_ptr         !! CHOLMOD's handle (fd_cholmod.c)
      real(dp) :: lnz = 0.0_dp                        !! entries of the factor (symbolic analysis)
      real(dp) :: flops = 0.0_dp                      !! flops of a factorization
      integer :: factorizations = 0                   !! numeric factorizations made
      integer :: changes = 0                          !! phase changes taken by the Woodbury identity
      real(dp), private :: c0 = 0.0_dp, c1 = 0.0_dp
      integer, allocatable, private :: colptr(:), rowind(:) !! upper triangle of K^, compressed columns
      integer, allocatable, private :: diag(:)        !! position of each diagonal entry
      real(dp), allocatable, private :: kv(:), cv(:), av(:) !! K, C and K^ on the pattern
      real(dp), allocatable, private :: mass(:)
      integer, allocatable, private :: dptr(:), ddof(:) !! the devices' terms
      real(dp), allocatable, private :: dcoef(:)
      integer, allocatable, private :: ppos(:), pptr(:) !! position of each pair of a device's terms
      real(dp), allocatable, private :: kd0(:)        !! device stiffness in the factor
      integer :: ns = 0                               !! devices in S (stiffness differs from kd0)
      integer, private :: smax = 0
      integer, allocatable, private :: sdev(:)        !! S's devices
      real(dp), allocatable, private :: w(:, :)       !! (n, smax) A0^-1 b_d of S's devices
      real(dp), allocatable, private :: cap(:, :)     !! LU factors of the capacitance
      integer, allocatable, private :: ipiv(:)
      real(dp), allocatable, private :: t(:)
      integer, allocatable, private :: slot(:)        !! device -> its column of w (0: none)
      logical, allocatable, private :: used(:)        !! work: a column of w still used
   end type sparse_system

contains

   !> Whether the build has CHOLMOD.
   logical function sparse_available()
      sparse_available = fd_chol_available() == 1
   end function sparse_available

   !> Half-bandwidth of K^'s graph in reverse Cuthill-McKee ordering (fd_banded's own band).
   function sparse_band(n, spring_i, spring_j, dev_ptr, dev_dof, dashpot_i, dashpot_j, kx_i, kx_j) result(kb)
      integer, intent(in) :: n                   !! DOFs
      integer, intent(in) :: spring_i(:), spring_j(:) !! springs' nodes (0 = table)
      integer, intent(in) :: dev_ptr(:), dev_dof(:)   !! devices' terms
      integer, intent(in) :: dashpot_i(:), dashpot_j(:) !! dashpots' nodes
      integer, intent(in), optional :: kx_i(:), kx_j(:) !! K_x's entries (none: not present)
      integer :: kb                              !! half-bandwidth
      integer, allocatable :: ei(:), ej(:), perm(:), inv(:), xi(:), xj(:)
      integer :: ne, d, p, q, i

      if (present(kx_i) .and. present(kx_j)) then
         xi = kx_i
         xj = kx_j
      else
         allocate (xi(0), xj(0))
      end if
      call edges(spring_i, spring_j, dev_ptr, dev_dof, xi, xj, dashpot_i, dashpot_j, ei, ej, ne)
      allocate (perm(n), inv(n))
      call rcm_order(n, ei(1:ne), ej(1:ne), perm)
      do i = 1, n
         inv(perm(i)) = i
      end do
      kb = graph_bandwidth(ei(1:ne), ej(1:ne), inv)
      do d = 1, size(dev_ptr) - 1
         do p = dev_ptr(d), dev_ptr(d + 1) - 1
            do q = p + 1, dev_ptr(d + 1) - 1
               kb = max(kb, abs(inv(dev_dof(p)) - inv(dev_dof(q))))
            end do
         end do
      end do
   end function sparse_band

   !> The graph's edges between two DOFs: springs, K_x off the diagonal, dashpots, and every
   !> pair of a device's terms.
   subroutine edges(spring_i, spring_j, dev_ptr, dev_dof, kx_i, kx_j, dashpot_i, dashpot_j, ei, ej, ne)
      integer, intent(in) :: spring_i(:), spring_j(:), dev_ptr(:), dev_dof(:), kx_i(:), kx_j(:)
      integer, intent(in) :: dashpot_i(:), dashpot_j(:)
      integer, allocatable, intent(out) :: ei(:), ej(:)
      integer, intent(out) :: ne
      integer :: m, d, p, q

      m = size(spring_i) + size(kx_i) + size(dashpot_i)
      do d = 1, size(dev_ptr) - 1
         m = m + (dev_ptr(d + 1) - dev_ptr(d))**2
      end do
      allocate (ei(m), ej(m))
      ne = 0
      call add(spring_i, spring_j)
      call add(kx_i, kx_j)
      call add(dashpot_i, dashpot_j)
      do d = 1, size(dev_ptr) - 1
         do p = dev_ptr(d), dev_ptr(d + 1) - 1
            do q = p + 1, dev_ptr(d + 1) - 1
               if (dev_dof(p) == dev_dof(q)) cycle
               ne = ne + 1
               ei(ne) = dev_dof(p)
               ej(ne) = dev_dof(q)
            end do
         end do
      end do
   contains
      subroutine add(a, b)
         integer, intent(in) :: a(:), b(:)
         integer :: k
         do k = 1, size(a)
            if (a(k) == 0 .or. b(k) == 0 .or. a(k) == b(k)) cycle
            ne = ne + 1
            ei(ne) = a(k)
            ej(ne) = b(k)
         end do
      end subroutine add
   end subroutine edges

   !> Set up the system: K^'s pattern and its analysis by CHOLMOD, K and C on it. The input is
   !> fd_banded's spd_setup's, checked there (the caller sets that up or has checked it).
   subroutine sparse_setup(sys, mass, spring_i, spring_j, spring_k, dev_ptr, dev_dof, dev_coef, a0, a1, &
                           dashpot_i, dashpot_j, dashpot_c, error, kx_i, kx_j, kx_v)
      type(sparse_system), intent(inout) :: sys  !! the system (freed first)
      real(dp), intent(in) :: mass(:)            !! masses [kg]
      integer, intent(in) :: spring_i(:), spring_j(:) !! springs' nodes (0 = table)
      real(dp), intent(in) :: spring_k(:)        !! their stiffness [N/m]
      integer, intent(in) :: dev_ptr(:), dev_dof(:) !! devices' terms
      real(dp), intent(in) :: dev_coef(:)        !! their coefficients
      real(dp), intent(in) :: a0, a1             !! C = a0 M + a1 K + dashpots
      integer, intent(in) :: dashpot_i(:), dashpot_j(:) !! dashpots' nodes
      real(dp), intent(in) :: dashpot_c(:)       !! their coefficients [N s/m]
      type(error_type), allocatable, intent(out) :: error !! no CHOLMOD, no memory
      integer, intent(in), optional :: kx_i(:), kx_j(:) !! K_x's entries (row <= column; none: not present)
      real(dp), intent(in), optional :: kx_v(:)  !! their values [N/m]
      integer, allocatable :: ei(:), ej(:), xi(:), xj(:)
      real(dp), allocatable :: xv(:)
      integer :: n, nd, ne, st, i, k, d, p, q, np
      real(dp) :: lnz, fl

      call sparse_free(sys)
      if (.not. sparse_available()) then
         call fatal_error(error, "this build has no sparse solver (CHOLMOD): set linear_system = 'banded' or 'auto', &
                          &or rebuild with SuiteSparse's CHOLMOD (libsuitesparse-dev)")
         return
      end if
      if (present(kx_i) .and. present(kx_j) .and. present(kx_v)) then
         xi = kx_i
         xj = kx_j
         xv = kx_v
      else
         allocate (xi(0), xj(0), xv(0))
      end if
      n = size(mass)
      nd = size(dev_ptr) - 1
      sys%n = n
      sys%nd = nd
      call edges(spring_i, spring_j, dev_ptr, dev_dof, xi, xj, dashpot_i, dashpot_j, ei, ej, ne)
      call pattern(n, ei(1:ne), ej(1:ne), sys%colptr, sys%rowind, sys%diag)
      np = size(sys%rowind)
      allocate (sys%kv(np), sys%cv(np), sys%av(np), sys%mass(n), sys%kd0(nd), sys%slot(nd), stat=st)
      if (st /= 0) then
         call fatal_error(error, "not enough memory for the sparse effective stiffness of "//trim(fmt_int(n))// &
                          " DOFs", stat_no_memory)
         return
      end if
      sys%mass = mass
      sys%kv = 0.0_dp
      sys%cv = 0.0_dp
      sys%av = 0.0_dp
      sys%kd0 = 0.0_dp
      sys%slot = 0
      do k = 1, size(spring_i)
         call add_link(sys, sys%kv, spring_i(k), spring_j(k), spring_k(k))
      end do
      do k = 1, size(xi)
         i = position(sys, min(xi(k), xj(k)), max(xi(k), xj(k)))
         sys%kv(i) = sys%kv(i) + xv(k)
      end do
      sys%cv = a1*sys%kv
      do i = 1, n
         sys%cv(sys%diag(i)) = sys%cv(sys%diag(i)) + a0*mass(i)
      end do
      do k = 1, size(dashpot_i)
         call add_link(sys, sys%cv, dashpot_i(k), dashpot_j(k), dashpot_c(k))
      end do
      ! the devices' terms and the position of each pair p <= q of them
      sys%dptr = dev_ptr
      sys%ddof = dev_dof
      sys%dcoef = dev_coef
      allocate (sys%pptr(nd + 1))
      sys%pptr(1) = 1
      do d = 1, nd
         k = dev_ptr(d + 1) - dev_ptr(d)
         sys%pptr(d + 1) = sys%pptr(d) + k*(k + 1)/2
      end do
      allocate (sys%ppos(sys%pptr(nd + 1) - 1))
      k = 0
      do d = 1, nd
         do p = dev_ptr(d), dev_ptr(d + 1) - 1
            do q = p, dev_ptr(d + 1) - 1
               k = k + 1
               sys%ppos(k) = position(sys, min(dev_dof(p), dev_dof(q)), max(dev_dof(p), dev_dof(q)))
            end do
         end do
      end do
      st = fd_chol_create(int(n, c_int), sys%colptr - 1, sys%rowind - 1, int(max(1, min(nd, changed_cap)), c_int), &
                          sys%h, lnz, fl)
      if (st /= chol_ok) then
         call chol_error(st, 0, error)
         return
      end if
      sys%lnz = lnz
      sys%flops = fl
      ! the Woodbury identity is cheaper than a factorization while n |S| stays below about the
      ! factor's entries
      sys%smax = max(1, min(nd, changed_cap, nint(lnz/real(n, dp))))
      allocate (sys%sdev(sys%smax), sys%w(n, sys%smax), sys%cap(sys%smax, sys%smax), sys%ipiv(sys%smax), &
                sys%t(sys%smax), sys%used(sys%smax), stat=st)
      if (st /= 0) then
         call fatal_error(error, "not enough memory for the sparse effective stiffness of "//trim(fmt_int(n))// &
                          " DOFs", stat_no_memory)
         return
      end if
   end subroutine sparse_setup

   !> The upper triangle's pattern in compressed columns: the diagonal and every edge.
   pure subroutine pattern(n, ei, ej, colptr, rowind, diag)
      integer, intent(in) :: n, ei(:), ej(:)
      integer, allocatable, intent(out) :: colptr(:), rowind(:), diag(:)
      integer, allocatable :: cnt(:), rows(:), mark(:)
      integer :: k, j, p, m

      allocate (cnt(n + 1), mark(n), diag(n))
      cnt = 0
      do k = 1, size(ei)
         j = max(ei(k), ej(k))
         cnt(j + 1) = cnt(j + 1) + 1
      end do
      cnt(1) = 1
      do j = 1, n
         cnt(j + 1) = cnt(j + 1) + cnt(j) + 1
      end do
      allocate (rows(cnt(n + 1) - 1))
      ! every column: its diagonal first, then the edges' rows (duplicates removed below)
      colptr = cnt
      do j = 1, n
         rows(cnt(j)) = j
         cnt(j) = cnt(j) + 1
      end do
      do k = 1, size(ei)
         j = max(ei(k), ej(k))
         rows(cnt(j)) = min(ei(k), ej(k))
         cnt(j) = cnt(j) + 1
      end do
      allocate (rowind(size(rows)))
      mark = 0
      m = 0
      cnt(1) = 1
      do j = 1, n
         p = m
         do k = colptr(j), colptr(j + 1) - 1
            if (mark(rows(k)) == j) cycle
            mark(rows(k)) = j
            m = m + 1
            rowind(m) = rows(k)
         end do
         call sort(rowind(p + 1:m))
         cnt(j + 1) = m + 1
         diag(j) = m
      end do
      colptr = cnt
      rowind = rowind(1:m)
   end subroutine pattern

   !> Insertion sort (a column's rows: a few).
   pure subroutine sort(a)
      integer, intent(inout) :: a(:)
      integer :: i, j, v

      do i = 2, size(a)
         v = a(i)
         j = i - 1
         do while (j >= 1)
            if (a(j) <= v) exit
            a(j + 1) = a(j)
            j = j - 1
         end do
         a(j + 1) = v
      end do
   end subroutine sort

   !> Position of entry (i, j), i <= j, in the pattern (binary search of column j).
   pure integer function position(sys, i, j) result(k)
      type(sparse_system), intent(in) :: sys
      integer, intent(in) :: i, j
      integer :: lo, hi

      lo = sys%colptr(j)
      hi = sys%colptr(j + 1) - 1
      do while (lo < hi)
         k = (lo + hi)/2
         if (sys%rowind(k) < i) then
            lo = k + 1
         else
            hi = k
         end if
      end do
      k = lo
   end function position

   !> A link of coefficient c between nodes i and j (0 = table) added to the values v.
   subroutine add_link(sys, v, i, j, c)
      type(sparse_system), intent(in) :: sys
      real(dp), intent(inout) :: v(:)
      integer, intent(in) :: i, j
      real(dp), intent(in) :: c

      if (i > 0) v(sys%diag(i)) = v(sys%diag(i)) + c
      if (j > 0) v(sys%diag(j)) = v(sys%diag(j)) + c
      if (i > 0 .and. j > 0 .and. i /= j) then
         v(position(sys, min(i, j), max(i, j))) = v(position(sys, min(i, j), max(i, j))) - c
      end if
      if (i > 0 .and. i == j) v(sys%diag(i)) = v(sys%diag(i)) - 2.0_dp*c
   end subroutine add_link

   !> Factor K^ = K + c1 C + c0 M + sum kd b b' (numerically, on the analysis of sparse_setup).
   subroutine sparse_factor(sys, c0, c1, kd, error)
      type(sparse_system), intent(inout) :: sys  !! the system, set up
      real(dp), intent(in) :: c0, c1             !! coefficients of M and C
      real(dp), intent(in) :: kd(:)              !! device stiffness [N/m], one per device
      type(error_type), allocatable, intent(out) :: error !! not positive definite (its DOF)
      integer :: i, d, p, q, k
      integer(c_int) :: st, col

      if (.not. c_associated(sys%h)) then
         call fatal_error(error, "sparse_factor: the system is not set up (sparse_setup)")
         return
      end if
      sys%c0 = c0
      sys%c1 = c1
      sys%av = sys%kv + c1*sys%cv
      do i = 1, sys%n
         sys%av(sys%diag(i)) = sys%av(sys%diag(i)) + c0*sys%mass(i)
      end do
      do d = 1, sys%nd
         k = sys%pptr(d) - 1
         do p = sys%dptr(d), sys%dptr(d + 1) - 1
            do q = p, sys%dptr(d + 1) - 1
               k = k + 1
               if (p == q) then
                  sys%av(sys%ppos(k)) = sys%av(sys%ppos(k)) + kd(d)*sys%dcoef(p)**2
               else if (sys%ddof(p) == sys%ddof(q)) then
                  sys%av(sys%ppos(k)) = sys%av(sys%ppos(k)) + 2.0_dp*kd(d)*sys%dcoef(p)*sys%dcoef(q)
               else
                  sys%av(sys%ppos(k)) = sys%av(sys%ppos(k)) + kd(d)*sys%dcoef(p)*sys%dcoef(q)
               end if
            end do
         end do
      end do
      st = fd_chol_factor(sys%h, sys%av, col)
      if (st /= chol_ok) then
         call chol_error(st, int(col), error)
         return
      end if
      sys%factorizations = sys%factorizations + 1
      sys%kd0 = kd
      sys%ns = 0
      sys%slot = 0
   end subroutine sparse_factor

   !> The factor for new device stiffnesses kd: the changed devices' terms by the Woodbury
   !> identity on the kept factor, or a new factorization when they are more than it takes.
   subroutine sparse_update_devices(sys, kd, error)
      type(sparse_system), intent(inout) :: sys  !! the system, factored
      real(dp), intent(in) :: kd(:)              !! device stiffness [N/m], one per device
      type(error_type), allocatable, intent(out) :: error !! not positive definite
      integer :: d, k, m, info, j

      m = count(kd /= sys%kd0)
      if (m > sys%smax) then
         call sparse_factor(sys, sys%c0, sys%c1, kd, error)
         return
      end if
      ! drop the columns of devices back at their factored stiffness, add the new ones
      sys%used = .false.
      do d = 1, sys%nd
         if (sys%slot(d) == 0) cycle
         if (kd(d) == sys%kd0(d)) then
            sys%slot(d) = 0
         else
            sys%used(sys%slot(d)) = .true.
         end if
      end do
      do d = 1, sys%nd
         if (kd(d) == sys%kd0(d) .or. sys%slot(d) /= 0) cycle
         k = findloc(sys%used, .false., 1)
         sys%used(k) = .true.
         sys%slot(d) = k
         sys%w(:, k) = 0.0_dp
         call add_term(sys, d, 1.0_dp, sys%w(:, k))
         call sparse_base_solve(sys, sys%w(:, k), error)
         if (allocated(error)) return
      end do
      ! S in device order, its capacitance diag(1 / (kd - kd0)) + B' W, LU-factored
      sys%ns = 0
      do d = 1, sys%nd
         if (sys%slot(d) == 0) cycle
         sys%ns = sys%ns + 1
         sys%sdev(sys%ns) = d
      end do
      sys%changes = sys%changes + 1
      if (sys%ns == 0) return
      do j = 1, sys%ns
         do k = 1, sys%ns
            sys%cap(k, j) = term_dot(sys, sys%sdev(k), sys%w(:, sys%slot(sys%sdev(j))))
         end do
         d = sys%sdev(j)
         sys%cap(j, j) = sys%cap(j, j) + 1.0_dp/(kd(d) - sys%kd0(d))
      end do
      call dgetrf(sys%ns, sys%ns, sys%cap, sys%smax, sys%ipiv, info)
      if (info /= 0) call sparse_factor(sys, sys%c0, sys%c1, kd, error)
   end subroutine sparse_update_devices

   !> y = y + alpha b_d.
   pure subroutine add_term(sys, d, alpha, y)
      type(sparse_system), intent(in) :: sys
      integer, intent(in) :: d
      real(dp), intent(in) :: alpha
      real(dp), intent(inout) :: y(:)
      integer :: p

      do p = sys%dptr(d), sys%dptr(d + 1) - 1
         y(sys%ddof(p)) = y(sys%ddof(p)) + alpha*sys%dcoef(p)
      end do
   end subroutine add_term

   !> b_d' x.
   pure real(dp) function term_dot(sys, d, x) result(s)
      type(sparse_system), intent(in) :: sys
      integer, intent(in) :: d
      real(dp), intent(in) :: x(:)
      integer :: p

      s = 0.0_dp
      do p = sys%dptr(d), sys%dptr(d + 1) - 1
         s = s + sys%dcoef(p)*x(sys%ddof(p))
      end do
   end function term_dot

   !> x := A0^-1 x with the kept factor.
   subroutine sparse_base_solve(sys, x, error)
      type(sparse_system), intent(inout) :: sys
      real(dp), intent(inout), contiguous :: x(:)
      type(error_type), allocatable, intent(out) :: error
      integer(c_int) :: st

      st = fd_chol_solve(sys%h, 1_c_int, x)
      if (st /= chol_ok) call chol_error(st, 0, error)
   end subroutine sparse_base_solve

   !> x := K^-1 x for the current device stiffnesses.
   subroutine sparse_solve(sys, x, error)
      type(sparse_system), intent(inout) :: sys  !! the system, factored
      real(dp), intent(inout), contiguous :: x(:) !! right-hand side on entry, solution on exit
      type(error_type), allocatable, intent(out) :: error !! the solver failed
      integer :: k, info

      call sparse_base_solve(sys, x, error)
      if (allocated(error) .or. sys%ns == 0) return
      do k = 1, sys%ns
         sys%t(k) = term_dot(sys, sys%sdev(k), x)
      end do
      call dgetrs('N', sys%ns, 1, sys%cap, sys%smax, sys%ipiv, sys%t, sys%smax, info)
      do k = 1, sys%ns
         x = x - sys%t(k)*sys%w(:, sys%slot(sys%sdev(k)))
      end do
   end subroutine sparse_solve

   !> X := A^-1 X for several right-hand sides with the factor alone (no device changes), up
   !> to min(devices, 64) at once.
   subroutine sparse_solve_many(sys, x, error)
      type(sparse_system), intent(inout) :: sys  !! the system, factored
      real(dp), intent(inout), contiguous :: x(:, :) !! (n, nrhs)
      type(error_type), allocatable, intent(out) :: error !! the solver failed
      integer(c_int) :: st

      st = fd_chol_solve(sys%h, int(size(x, 2), c_int), x)
      if (st /= chol_ok) call chol_error(st, 0, error)
   end subroutine sparse_solve_many

   !> y = beta y + alpha K x (K in the original numbering).
   subroutine sparse_k_matvec(sys, x, y, alpha, beta)
      type(sparse_system), intent(in) :: sys   !! the system
      real(dp), intent(in) :: x(:)             !! vector
      real(dp), intent(inout) :: y(:)          !! result
      real(dp), intent(in) :: alpha, beta      !! factors
      call symv(sys, sys%kv, x, y, alpha, beta)
   end subroutine sparse_k_matvec

   !> y = beta y + alpha C x.
   subroutine sparse_c_matvec(sys, x, y, alpha, beta)
      type(sparse_system), intent(in) :: sys   !! the system
      real(dp), intent(in) :: x(:)             !! vector
      real(dp), intent(inout) :: y(:)          !! result
      real(dp), intent(in) :: alpha, beta      !! factors
      call symv(sys, sys%cv, x, y, alpha, beta)
   end subroutine sparse_c_matvec

   !> y = y + alpha (K x + C v).
   subroutine sparse_kc_matvec(sys, x, v, y, alpha)
      type(sparse_system), intent(in) :: sys   !! the system
      real(dp), intent(in) :: x(:), v(:)       !! vectors
      real(dp), intent(inout) :: y(:)          !! result
      real(dp), intent(in) :: alpha            !! factor
      call symv(sys, sys%kv, x, y, alpha, 1.0_dp)
      call symv(sys, sys%cv, v, y, alpha, 1.0_dp)
   end subroutine sparse_kc_matvec

   !> y = beta y + alpha A x, A symmetric with upper triangle a on the pattern.
   pure subroutine symv(sys, a, x, y, alpha, beta)
      type(sparse_system), intent(in) :: sys
      real(dp), intent(in) :: a(:), x(:), alpha, beta
      real(dp), intent(inout) :: y(:)
      integer :: j, k, i
      real(dp) :: s, xj

      if (beta /= 1.0_dp) y = beta*y
      do j = 1, sys%n
         s = 0.0_dp
         xj = alpha*x(j)
         do k = sys%colptr(j), sys%colptr(j + 1) - 2
            i = sys%rowind(k)
            s = s + a(k)*x(i)
            y(i) = y(i) + a(k)*xj
         end do
         k = sys%colptr(j + 1) - 1
         y(j) = y(j) + alpha*s + a(k)*xj
      end do
   end subroutine symv

   !> Entries of the factor (CHOLMOD's symbolic analysis).
   pure real(dp) function sparse_factor_entries(sys)
      type(sparse_system), intent(in) :: sys
      sparse_factor_entries = sys%lnz
   end function sparse_factor_entries

   !> Entries of K^'s upper triangle.
   pure integer function sparse_nonzeros(sys)
      type(sparse_system), intent(in) :: sys
      sparse_nonzeros = 0
      if (allocated(sys%rowind)) sparse_nonzeros = size(sys%rowind)
   end function sparse_nonzeros

   !> Bytes the factor holds.
   real(dp) function sparse_factor_bytes(sys)
      type(sparse_system), intent(in) :: sys
      sparse_factor_bytes = 0.0_dp
      if (c_associated(sys%h)) sparse_factor_bytes = fd_chol_factor_bytes(sys%h)
   end function sparse_factor_bytes

   !> Free the system: CHOLMOD's part and every array (it may be set up again).
   subroutine sparse_free(sys)
      type(sparse_system), intent(inout) :: sys  !! the system
      type(sparse_system) :: empty
      if (c_associated(sys%h)) call fd_chol_free(sys%h)
      sys = empty
   end subroutine sparse_free

   !> An error of the interface, as text.
   subroutine chol_error(st, col, error)
      integer(c_int), intent(in) :: st
      integer, intent(in) :: col
      type(error_type), allocatable, intent(out) :: error

      select case (st)
      case (chol_unavailable)
         call fatal_error(error, "this build has no sparse solver (CHOLMOD)")
      case (chol_no_memory)
         call fatal_error(error, "not enough memory for the sparse factor (CHOLMOD)", stat_no_memory)
      case (chol_not_posdef)
         call fatal_error(error, "the effective stiffness is not positive definite: the sparse factorization &
                          &fails at DOF "//trim(fmt_int(col)))
      case default
         call fatal_error(error, "the sparse solver (CHOLMOD) failed, status "//trim(fmt_int(int(st))))
      end select
   end subroutine chol_error

end module fd_sparse
