!> Linear complementarity solvers: the standard LCP and the box-constrained (mixed) LCP of
!> Coulomb friction, by Lemke's complementary pivoting, exact enumeration of complementary
!> patterns, and projected Gauss-Seidel (PGS).
!>
!> **Standard LCP(q, M).** Find z with w = M z + q, w >= 0, z >= 0, w'z = 0.
!>
!> **Box LCP(q, M, lo, hi)** (a mixed LCP). Find lo <= z <= hi with w = M z + q and
!>   z_i = lo_i => w_i >= 0,  z_i = hi_i => w_i <= 0,  lo_i < z_i < hi_i => w_i = 0,
!> i.e. z = clamp(z - w, lo, hi) (the natural map). The bounds are finite, lo <= hi; a
!> fixed variable (lo_i = hi_i) leaves w_i free.
!>
!> **Friction.** For the devices that may stick (zero relative velocity) with forces F (the
!> structure carries -B F, B = [b_d], s_d = b_d' u), M u'' = p - B F gives the relative
!> accelerations s'' = B' M^-1 p - B' M^-1 B F. Coulomb's law (|F| <= P mu; F = +P mu only if
!> s'' >= 0, F = -P mu only if s'' <= 0, s'' = 0 in between) is exactly the box LCP
!>   z = F, lo = -P mu, hi = +P mu, w = -s'',  M = B' M^-1 B (the Delassus operator),
!>   q = -B' M^-1 p
!> (p: every force but the friction of these devices). Moreau-Jean time stepping gives the
!> same problem with impulses (bounds P mu h) and end-of-step relative velocities, M being
!> the Delassus operator of the step's iteration matrix.
!>
!> **Existence and uniqueness.**
!> - M a P-matrix (every principal minor > 0: symmetric positive definite, strictly
!>   diagonally dominant with a positive diagonal, triangular with a positive diagonal):
!>   the standard LCP has exactly one solution for every q and Lemke's method finds it (it
!>   never ends on a secondary ray); the box LCP too has exactly one solution for every q
!>   and every box (Facchinei and Pang 2003, ch. 3).
!> - M positive semidefinite (x'Mx >= 0, symmetric or not; copositive-plus): Lemke's
!>   method with the lexicographic rule ends either with a solution or on a secondary ray,
!>   and the ray proves that no z >= 0 has M z + q >= 0 (Cottle, Pang and Stone, The Linear
!>   Complementarity Problem, 1992, sec. 4.4). Feasible means solvable.
!> - M symmetric positive semidefinite, standard or box LCP: if z1, z2 both solve, then
!>   w1'(z2 - z1) >= 0 and w2'(z1 - z2) >= 0 give (z1 - z2)'M(z1 - z2) <= 0, so
!>   M (z1 - z2) = 0 and w1 = w2: w is unique, z in general not.
!> - Box LCP with finite bounds: a solution exists for every M (a variational inequality on
!>   a nonempty compact convex set, Hartman-Stampacchia). For friction, M = B' M^-1 B is
!>   symmetric positive semidefinite (singular when devices are redundant: two devices in
!>   parallel, a closed loop); then w (the relative accelerations) is unique, and so is
!>   B z (z1 - z2 in the null space of B' M^-1 B is in the null space of B), hence every
!>   acceleration M^-1 (p - B z) of the structure; the split of the forces among redundant
!>   devices is not.
!>
!> **Methods.**
!> - Lemke (`lcp_lemke`): covering vector d = 1, complementary pivoting on a dense
!>   tableau, lexicographic minimum-ratio rule (the rows of the basis inverse break ties;
!>   z0 leaves whenever it ties), so it cannot cycle; a pivot cap (`max_pivots`). The
!>   problem is scaled symmetrically first (D M D with unit diagonal, q by its largest
!>   entry), and the result is polished: the final pattern's linear system is solved again
!>   on the original data with one step of iterative refinement.
!> - Box LCP by Lemke (`box_lcp_lemke`): with z = lo + x, u = hi - lo, w = a - b it is the
!>   standard LCP of size 2n in (x, b):
!>     a = M x + (q + M lo) + b >= 0, x >= 0, a'x = 0;   y = u - x >= 0, b >= 0, y'b = 0,
!>   whose matrix [[M, I], [-I, 0]] is positive semidefinite whenever M is (the off-diagonal
!>   blocks cancel in Z'M Z) and which is always feasible (x = 0, b large): for a positive
!>   semidefinite M, Lemke always finds a solution. x nonbasic: z at lo; y nonbasic: z at
!>   hi; both basic: z between the bounds.
!> - Enumeration (`lcp_enumerate`, `box_lcp_enumerate`): every pattern (2^n: z_i = 0 or
!>   w_i = 0; 3^n for the box: at lo, at hi or free), the free block solved by Gaussian
!>   elimination with complete pivoting (singular blocks: consistency checked, basic
!>   solution tried). It is complete when every solution can be reached through a
!>   nonsingular free block (P-matrices; symmetric positive semidefinite M, whose solutions
!>   can be moved along null vectors until one is); it proves infeasibility of a standard
!>   LCP only when no pattern was singular-consistent or a near miss. Limits `enum_max`
!>   (standard, 2^n patterns) and `box_enum_max` (3^n).
!> - PGS (`lcp_pgs`, `box_lcp_pgs`): z_i <- clamp(z_i - w_i / M_ii, lo_i, hi_i) sweep after
!>   sweep, from the caller's z (warm start): coordinate descent on 1/2 z'Mz + q'z over the
!>   box when M is symmetric. It converges for symmetric positive definite M, and for a box
!>   LCP with symmetric positive semidefinite M and a positive diagonal (Luo and Tseng
!>   1992), at a linear rate set by the conditioning. It stops when the residual is below
!>   `pgs_tol`, else reports lcp_not_converged.
!> - `lcp_solve`, `box_lcp_solve`: Lemke, then enumeration when Lemke fails and n is small.
!>
!> **Every returned z is checked.** z is clipped into its bounds (z >= 0, lo <= z <= hi
!> hold exactly), w = M z + q is computed from it, and the relative residual (see
!> `lcp_residual`) must be <= `tol` (PGS: `pgs_tol`) for lcp_solved; otherwise the status
!> says why. z and w mean nothing unless the status is lcp_solved.
!>
!> No procedure stops or prints. Only `lcp_init` allocates: it sizes a workspace once, and
!> every solver works in it, so a call inside a time-step loop allocates nothing.
module fd_lcp
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int
   implicit none
   private

   public :: lcp_work, lcp_info, lcp_init
   public :: lcp_solve, lcp_lemke, lcp_enumerate, lcp_pgs
   public :: box_lcp_solve, box_lcp_lemke, box_lcp_enumerate, box_lcp_pgs
   public :: lcp_residual, box_lcp_residual, lcp_status_text
   public :: lcp_solved, lcp_infeasible, lcp_ray, lcp_not_found, lcp_pivot_limit, lcp_not_converged, &
             lcp_inaccurate, lcp_too_large, lcp_bad_input
   public :: lcp_method_lemke, lcp_method_enumeration, lcp_method_pgs

   integer, parameter :: lcp_solved = 0        !! z solves the problem (residual <= tolerance)
   integer, parameter :: lcp_infeasible = 1    !! proven: no solution (standard LCP, enumeration)
   integer, parameter :: lcp_ray = 2           !! Lemke ended on a secondary ray (M PSD: infeasible)
   integer, parameter :: lcp_not_found = 3     !! enumeration found none but cannot prove there is none
   integer, parameter :: lcp_pivot_limit = 4   !! Lemke reached max_pivots
   integer, parameter :: lcp_not_converged = 5 !! PGS reached pgs_max_sweeps above pgs_tol
   integer, parameter :: lcp_inaccurate = 6    !! a candidate was found but failed the residual check
   integer, parameter :: lcp_too_large = 7     !! n above the enumeration limit
   integer, parameter :: lcp_bad_input = 8     !! sizes, non-finite data, lo > hi, M_ii <= 0 (PGS), no workspace

   integer, parameter :: lcp_method_lemke = 1       !! z came from Lemke's method
   integer, parameter :: lcp_method_enumeration = 2 !! z came from the enumeration of patterns
   integer, parameter :: lcp_method_pgs = 3         !! z came from projected Gauss-Seidel

   integer, parameter :: at_lo = 0, at_hi = 1, free = 2   !! pattern of one variable
   integer, parameter :: max_enum_bits = 30
   real(dp), parameter :: piv_rel = 1.0e-12_dp   !! Lemke: smallest pivot, relative to the column
   real(dp), parameter :: tie_rel = 1.0e-12_dp   !! Lemke: ratios this close are ties
   real(dp), parameter :: rank_rel = 1.0e-12_dp  !! elimination: pivot below this (scaled) is zero
   real(dp), parameter :: cons_rel = 1.0e-10_dp  !! elimination: consistency of a singular block
   real(dp), parameter :: near_miss = 1.0e-6_dp  !! enumeration: a rejected pattern this close is inconclusive

   !> What a solver did: status, method, work, and the residual of the returned z.
   type :: lcp_info
      integer :: status = lcp_bad_input   !! lcp_solved, or why not (lcp_* status codes)
      integer :: method = 0               !! lcp_method_* that produced z (0: none)
      integer :: iterations = 0           !! pivots (Lemke), patterns tried (enumeration), sweeps (PGS)
      real(dp) :: residual = huge(1.0_dp) !! relative residual of the returned z (lcp_residual)
   end type lcp_info

   !> Workspace of the solvers, sized once by lcp_init; the settings may be changed after.
   type :: lcp_work
      real(dp) :: tol = 1.0e-10_dp      !! residual accepted from Lemke and enumeration
      real(dp) :: pgs_tol = 1.0e-10_dp  !! residual at which PGS stops
      integer :: max_pivots = 0         !! Lemke's pivot cap; 0: 20 N + 100 (N = n, or 2 n for a box)
      integer :: pgs_max_sweeps = 10000 !! PGS sweep cap
      integer :: enum_max = 12          !! largest n enumerated for the standard LCP (2^n patterns)
      integer :: box_enum_max = 8       !! largest n enumerated for the box LCP (3^n patterns)
      integer, private :: nmax = 0      !! largest n of any solver
      integer, private :: pmax = 0      !! largest n of the pivoting methods
      real(dp), allocatable, private :: tab(:, :)            !! Lemke tableau [I, -M, -d, q]
      real(dp), allocatable, private :: col(:)               !! entering column
      integer, allocatable, private :: basis(:), cand(:), pos(:)
      real(dp), allocatable, private :: dsc(:), blo(:), bhi(:), zb(:), zt(:), wt(:)
      integer, allocatable, private :: state(:)
      real(dp), allocatable, private :: amat(:, :), a0(:, :), rv(:), r0(:), xv(:), dx(:), ds(:)
      integer, allocatable, private :: ip(:), jp(:), idx(:)
   end type lcp_work

contains

   !> Size a workspace once: every solver for n <= nmax, Lemke and enumeration for
   !> n <= pivot_max (their tableau holds 2 pivot_max x (4 pivot_max + 2) reals).
   subroutine lcp_init(work, nmax, pivot_max, error)
      type(lcp_work), intent(out) :: work                 !! the workspace
      integer, intent(in) :: nmax                         !! largest problem size (>= 1)
      integer, intent(in) :: pivot_max                    !! largest size for Lemke/enumeration (0..nmax)
      type(error_type), allocatable, intent(out) :: error !! nmax or pivot_max out of range
      integer :: p

      if (nmax < 1) then
         call fatal_error(error, 'lcp_init: nmax = '//trim(fmt_int(nmax))//' must be at least 1')
         return
      end if
      if (pivot_max < 0 .or. pivot_max > nmax) then
         call fatal_error(error, 'lcp_init: pivot_max = '//trim(fmt_int(pivot_max))// &
                          ' must be between 0 and nmax = '//trim(fmt_int(nmax)))
         return
      end if
      p = pivot_max
      work%nmax = nmax
      work%pmax = p
      allocate (work%tab(2*p, 4*p + 2), work%col(2*p), work%basis(2*p), work%cand(2*p), &
                work%pos(4*p + 1))
      allocate (work%dsc(nmax), work%blo(nmax), work%bhi(nmax), work%zb(nmax), work%zt(nmax), &
                work%wt(nmax), work%state(nmax))
      allocate (work%amat(p, p), work%a0(p, p), work%rv(p), work%r0(p), work%xv(p), work%dx(p), &
                work%ds(p), work%ip(p), work%jp(p), work%idx(p))
   end subroutine lcp_init

   ! ------------------------------------------------------------------ standard LCP

   !> Standard LCP by Lemke's method; if that fails and n <= enum_max, by enumeration.
   pure subroutine lcp_solve(work, m, q, z, w, info)
      type(lcp_work), intent(inout) :: work !! workspace from lcp_init
      real(dp), intent(in) :: m(:, :)       !! n x n matrix
      real(dp), intent(in) :: q(:)          !! n vector
      real(dp), intent(out) :: z(:)         !! solution (meaningful only if solved)
      real(dp), intent(out) :: w(:)         !! M z + q
      type(lcp_info), intent(out) :: info   !! status, method, pivots or patterns, residual
      type(lcp_info) :: first

      call lcp_lemke(work, m, q, z, w, first)
      info = first
      if (first%status == lcp_solved .or. first%status == lcp_bad_input) return
      if (size(q) > min(work%enum_max, work%pmax, max_enum_bits)) return
      call lcp_enumerate(work, m, q, z, w, info)
      if (info%status == lcp_solved .or. info%status == lcp_infeasible) return
      info = first
      call clear(z, w)
   end subroutine lcp_solve

   !> Standard LCP by Lemke's complementary pivoting (lexicographic rule, covering vector 1).
   pure subroutine lcp_lemke(work, m, q, z, w, info)
      type(lcp_work), intent(inout) :: work !! workspace from lcp_init
      real(dp), intent(in) :: m(:, :)       !! n x n matrix
      real(dp), intent(in) :: q(:)          !! n vector
      real(dp), intent(out) :: z(:)         !! solution (meaningful only if solved)
      real(dp), intent(out) :: w(:)         !! M z + q
      type(lcp_info), intent(out) :: info   !! status, pivots, residual
      integer :: n, i, j, nn, irhs
      real(dp) :: s

      call enter(work, lcp_method_lemke, m, q, z, w, info)
      if (info%status /= lcp_solved) return
      n = size(q)
      call unit_scaling(work, m, n)
      s = 0.0_dp
      do i = 1, n
         s = max(s, abs(work%dsc(i)*q(i)))
      end do
      if (s == 0.0_dp) s = 1.0_dp
      nn = n
      irhs = 2*nn + 2
      work%tab(1:nn, 1:irhs) = 0.0_dp
      do j = 1, n
         work%tab(j, j) = 1.0_dp
         do i = 1, n
            work%tab(i, n + j) = -work%dsc(i)*m(i, j)*work%dsc(j)
         end do
      end do
      do i = 1, n
         work%tab(i, 2*nn + 1) = -1.0_dp
         work%tab(i, irhs) = work%dsc(i)*q(i)/s
      end do
      call lemke_pivots(work, nn, info, z, w)
      if (info%status /= lcp_solved) return
      work%zb(1:n) = 0.0_dp
      work%state(1:n) = at_lo
      do i = 1, nn
         j = work%basis(i) - nn
         if (j >= 1 .and. j <= n) then
            work%zb(j) = work%dsc(j)*s*work%tab(i, irhs)
            work%state(j) = free
         end if
      end do
      call finish(work, m, q, n, .false., z, w, info)
   end subroutine lcp_lemke

   !> Standard LCP by enumeration of the 2^n complementary patterns (n <= enum_max).
   pure subroutine lcp_enumerate(work, m, q, z, w, info)
      type(lcp_work), intent(inout) :: work !! workspace from lcp_init
      real(dp), intent(in) :: m(:, :)       !! n x n matrix
      real(dp), intent(in) :: q(:)          !! n vector
      real(dp), intent(out) :: z(:)         !! solution (meaningful only if solved)
      real(dp), intent(out) :: w(:)         !! M z + q
      type(lcp_info), intent(out) :: info   !! status, patterns tried, residual
      integer :: n, i, mask, flag
      logical :: inconclusive
      real(dp) :: res

      call enter(work, lcp_method_enumeration, m, q, z, w, info)
      if (info%status /= lcp_solved) return
      n = size(q)
      inconclusive = .false.
      do mask = 0, 2**n - 1
         do i = 1, n
            work%state(i) = merge(free, at_lo, btest(mask, i - 1))
         end do
         call try_pattern(work, m, q, n, .false., z, w, flag, res)
         if (flag == 2) cycle
         if (res <= work%tol) then
            info%status = lcp_solved
            info%iterations = mask + 1
            info%residual = res
            return
         end if
         if (flag == 1 .or. res <= near_miss) inconclusive = .true.
      end do
      info%iterations = 2**n
      info%status = merge(lcp_not_found, lcp_infeasible, inconclusive)
      call clear(z, w)
   end subroutine lcp_enumerate

   !> Standard LCP by projected Gauss-Seidel from the z given (needs M_ii > 0).
   pure subroutine lcp_pgs(work, m, q, z, w, info)
      type(lcp_work), intent(inout) :: work !! workspace from lcp_init
      real(dp), intent(in) :: m(:, :)       !! n x n matrix, positive diagonal
      real(dp), intent(in) :: q(:)          !! n vector
      real(dp), intent(inout) :: z(:)       !! initial guess on entry (0 is fine); the last iterate
      real(dp), intent(out) :: w(:)         !! M z + q
      type(lcp_info), intent(out) :: info   !! status, sweeps, residual

      call enter(work, lcp_method_pgs, m, q, z, w, info)
      if (info%status /= lcp_solved) return
      call pgs_core(work, m, q, .false., z, w, info)
   end subroutine lcp_pgs

   ! ------------------------------------------------------------------ box LCP

   !> Box LCP by Lemke's method on its standard form of size 2n; if that fails and
   !> n <= box_enum_max, by enumeration.
   pure subroutine box_lcp_solve(work, m, q, lo, hi, z, w, info)
      type(lcp_work), intent(inout) :: work !! workspace from lcp_init
      real(dp), intent(in) :: m(:, :)       !! n x n matrix
      real(dp), intent(in) :: q(:)          !! n vector
      real(dp), intent(in) :: lo(:), hi(:)  !! finite bounds, lo <= hi
      real(dp), intent(out) :: z(:)         !! solution (meaningful only if solved)
      real(dp), intent(out) :: w(:)         !! M z + q
      type(lcp_info), intent(out) :: info   !! status, method, pivots or patterns, residual
      type(lcp_info) :: first

      call box_lcp_lemke(work, m, q, lo, hi, z, w, first)
      info = first
      if (first%status == lcp_solved .or. first%status == lcp_bad_input) return
      if (size(q) > min(work%box_enum_max, work%pmax, max_enum_bits)) return
      call box_lcp_enumerate(work, m, q, lo, hi, z, w, info)
      if (info%status == lcp_solved) return
      info = first
      call clear(z, w)
   end subroutine box_lcp_solve

   !> Box LCP by Lemke's method on the standard LCP of size 2n in (x, b), z = lo + x
   !> (see the module header); needs pivot_max >= n.
   pure subroutine box_lcp_lemke(work, m, q, lo, hi, z, w, info)
      type(lcp_work), intent(inout) :: work !! workspace from lcp_init
      real(dp), intent(in) :: m(:, :)       !! n x n matrix
      real(dp), intent(in) :: q(:)          !! n vector
      real(dp), intent(in) :: lo(:), hi(:)  !! finite bounds, lo <= hi
      real(dp), intent(out) :: z(:)         !! solution (meaningful only if solved)
      real(dp), intent(out) :: w(:)         !! M z + q
      type(lcp_info), intent(out) :: info   !! status, pivots, residual
      integer :: n, nn, i, j, irhs, r
      real(dp) :: s, acc

      call enter(work, lcp_method_lemke, m, q, z, w, info, lo, hi)
      if (info%status /= lcp_solved) return
      n = size(q)
      call unit_scaling(work, m, n)
      nn = 2*n
      irhs = 2*nn + 2
      ! scaled data: M' = D M D, u' = (hi - lo)/D, q_x = D (q + M lo); all divided by s
      s = 0.0_dp
      do i = 1, n
         acc = q(i)
         do j = 1, n
            acc = acc + m(i, j)*lo(j)
         end do
         work%zb(i) = work%dsc(i)*acc
         s = max(s, abs(work%zb(i)), (hi(i) - lo(i))/work%dsc(i))
      end do
      if (s == 0.0_dp) s = 1.0_dp
      work%tab(1:nn, 1:irhs) = 0.0_dp
      do i = 1, nn
         work%tab(i, i) = 1.0_dp
         work%tab(i, 2*nn + 1) = -1.0_dp
      end do
      do j = 1, n
         do i = 1, n
            work%tab(i, nn + j) = -work%dsc(i)*m(i, j)*work%dsc(j)
         end do
         work%tab(j, nn + n + j) = -1.0_dp
         work%tab(n + j, nn + j) = 1.0_dp
         work%tab(j, irhs) = work%zb(j)/s
         work%tab(n + j, irhs) = (hi(j) - lo(j))/work%dsc(j)/s
      end do
      call lemke_pivots(work, nn, info, z, w)
      if (info%status /= lcp_solved) return
      work%pos(1:2*nn + 1) = 0
      do r = 1, nn
         work%pos(work%basis(r)) = r
      end do
      do i = 1, n
         if (work%pos(nn + i) == 0) then           ! x_i = 0
            work%state(i) = at_lo
            work%zb(i) = lo(i)
         else if (work%pos(n + i) == 0) then       ! y_i = u_i - x_i = 0
            work%state(i) = at_hi
            work%zb(i) = hi(i)
         else
            work%state(i) = free
            work%zb(i) = lo(i) + work%dsc(i)*s*work%tab(work%pos(nn + i), irhs)
         end if
      end do
      call finish(work, m, q, n, .true., z, w, info)
   end subroutine box_lcp_lemke

   !> Box LCP by enumeration of the 3^n patterns (at lo, at hi, free; a fixed variable
   !> lo_i = hi_i has one), n <= box_enum_max. A solution always exists: finding none
   !> is lcp_not_found, never lcp_infeasible.
   pure subroutine box_lcp_enumerate(work, m, q, lo, hi, z, w, info)
      type(lcp_work), intent(inout) :: work !! workspace from lcp_init
      real(dp), intent(in) :: m(:, :)       !! n x n matrix
      real(dp), intent(in) :: q(:)          !! n vector
      real(dp), intent(in) :: lo(:), hi(:)  !! finite bounds, lo <= hi
      real(dp), intent(out) :: z(:)         !! solution (meaningful only if solved)
      real(dp), intent(out) :: w(:)         !! M z + q
      type(lcp_info), intent(out) :: info   !! status, patterns tried, residual
      integer :: n, i, flag, count
      real(dp) :: res

      call enter(work, lcp_method_enumeration, m, q, z, w, info, lo, hi)
      if (info%status /= lcp_solved) return
      n = size(q)
      work%state(1:n) = at_lo
      count = 0
      do
         count = count + 1
         call try_pattern(work, m, q, n, .true., z, w, flag, res)
         if (res <= work%tol) then
            info%status = lcp_solved
            info%iterations = count
            info%residual = res
            return
         end if
         ! next pattern: a counter in base 3 over the variables that are not fixed
         i = 1
         do while (i <= n)
            if (lo(i) < hi(i)) then
               if (work%state(i) < free) then
                  work%state(i) = work%state(i) + 1
                  exit
               end if
               work%state(i) = at_lo
            end if
            i = i + 1
         end do
         if (i > n) exit
      end do
      info%iterations = count
      info%status = lcp_not_found
      call clear(z, w)
   end subroutine box_lcp_enumerate

   !> Box LCP by projected Gauss-Seidel from the z given (needs M_ii > 0).
   pure subroutine box_lcp_pgs(work, m, q, lo, hi, z, w, info)
      type(lcp_work), intent(inout) :: work !! workspace from lcp_init
      real(dp), intent(in) :: m(:, :)       !! n x n matrix, positive diagonal
      real(dp), intent(in) :: q(:)          !! n vector
      real(dp), intent(in) :: lo(:), hi(:)  !! finite bounds, lo <= hi
      real(dp), intent(inout) :: z(:)       !! initial guess on entry (0 is fine); the last iterate
      real(dp), intent(out) :: w(:)         !! M z + q
      type(lcp_info), intent(out) :: info   !! status, sweeps, residual

      call enter(work, lcp_method_pgs, m, q, z, w, info, lo, hi)
      if (info%status /= lcp_solved) return
      call pgs_core(work, m, q, .true., z, w, info)
   end subroutine box_lcp_pgs

   ! ------------------------------------------------------------------ residuals, messages

   !> Relative residual of a standard LCP solution: with zs = max |z_i| and
   !> ws = max_i (|q_i| + sum_j |M_ij| zs) (each 1 if zero): the size w's terms have at the
   !> solution's scale (with |M_ij z_j| in its place, data q near zero, e.g. subnormal,
   !> made zs/ws overflow and a solution's w of 1e-309 count as a residual of 1),
   !>   max( max_i |w_i - (M z + q)_i| / ws,  max_i |min(z_i, w_i zs/ws)| / zs ),
   !> zero exactly when z solves the LCP; it measures infeasibility and complementarity.
   pure function lcp_residual(m, q, z, w) result(res)
      real(dp), intent(in) :: m(:, :) !! n x n matrix
      real(dp), intent(in) :: q(:)    !! n vector
      real(dp), intent(in) :: z(:)    !! candidate solution
      real(dp), intent(in) :: w(:)    !! its w
      real(dp) :: res                 !! relative residual

      res = residual_core(m, q, z, w, .false., q, q)
   end function lcp_residual

   !> Relative residual of a box LCP solution: as lcp_residual with the natural map
   !> |z_i - clamp(z_i - w_i zs/ws, lo_i, hi_i)| / zs, zs also covering the bounds.
   pure function box_lcp_residual(m, q, lo, hi, z, w) result(res)
      real(dp), intent(in) :: m(:, :)      !! n x n matrix
      real(dp), intent(in) :: q(:)         !! n vector
      real(dp), intent(in) :: lo(:), hi(:) !! bounds
      real(dp), intent(in) :: z(:)         !! candidate solution
      real(dp), intent(in) :: w(:)         !! its w
      real(dp) :: res                      !! relative residual

      res = residual_core(m, q, z, w, .true., lo, hi)
   end function box_lcp_residual

   !> What a status code means, for messages (trim the result).
   pure function lcp_status_text(status) result(text)
      integer, intent(in) :: status !! an lcp_* status code
      character(len=120) :: text    !! its meaning

      select case (status)
      case (lcp_solved)
         text = 'solved'
      case (lcp_infeasible)
         text = 'no solution exists (every complementary pattern checked)'
      case (lcp_ray)
         text = 'no solution found: Lemke''s method ended on a secondary ray (infeasible if M is positive semidefinite)'
      case (lcp_not_found)
         text = 'no solution found by enumeration (singular or borderline patterns: not a proof)'
      case (lcp_pivot_limit)
         text = 'no solution found: Lemke''s method reached its pivot limit'
      case (lcp_not_converged)
         text = 'projected Gauss-Seidel did not converge within its sweep limit'
      case (lcp_inaccurate)
         text = 'the solution found fails the residual check (ill-conditioned problem)'
      case (lcp_too_large)
         text = 'too many variables for enumeration'
      case (lcp_bad_input)
         text = 'bad input: sizes, non-finite values, lo > hi, M_ii <= 0 for PGS, or workspace too small'
      case default
         text = 'unknown status'
      end select
   end function lcp_status_text

   ! ------------------------------------------------------------------ internals

   !> lemke_core on the tableau the caller set, its status and pivots in info; z and w
   !> cleared when it does not solve.
   pure subroutine lemke_pivots(work, nn, info, z, w)
      type(lcp_work), intent(inout) :: work
      integer, intent(in) :: nn
      type(lcp_info), intent(inout) :: info
      real(dp), intent(inout) :: z(:), w(:)
      call lemke_core(work, nn, info%status, info%iterations)
      if (info%status /= lcp_solved) call clear(z, w)
   end subroutine lemke_pivots

   !> Lemke's method on the tableau [I, -M, -d, q] (nn rows, d = 1, basis = the w's),
   !> set by the caller in work%tab(1:nn, 1:2 nn + 2). On lcp_solved work%basis holds the
   !> final basis and the last tableau column the values of the basic variables.
   pure subroutine lemke_core(work, nn, status, pivots)
      type(lcp_work), intent(inout) :: work
      integer, intent(in) :: nn
      integer, intent(out) :: status, pivots
      integer :: iz0, irhs, e, r, leaving, maxp, i, k
      real(dp) :: cmax, ptol

      iz0 = 2*nn + 1
      irhs = 2*nn + 2
      pivots = 0
      do i = 1, nn
         work%basis(i) = i
      end do
      if (minval(work%tab(1:nn, irhs)) >= 0.0_dp) then
         status = lcp_solved          ! z = 0
         return
      end if
      maxp = work%max_pivots
      if (maxp <= 0) maxp = 20*nn + 100
      ! z0 enters at the value that makes the most negative q_i zero (lexicographically)
      e = iz0
      do i = 1, nn
         work%col(i) = 1.0_dp
         work%cand(i) = i
      end do
      call select_row(work, nn, nn, .false., r)
      do
         call pivot(work, nn, r, e)
         pivots = pivots + 1
         leaving = work%basis(r)
         work%basis(r) = e
         if (leaving == iz0) then
            status = lcp_solved
            return
         end if
         if (pivots >= maxp) then
            status = lcp_pivot_limit
            return
         end if
         ! the complement of the variable that left enters
         if (leaving <= nn) then
            e = leaving + nn
         else
            e = leaving - nn
         end if
         cmax = 0.0_dp
         do i = 1, nn
            work%col(i) = work%tab(i, e)
            cmax = max(cmax, abs(work%col(i)))
         end do
         ptol = piv_rel*max(1.0_dp, cmax)
         k = 0
         do i = 1, nn
            if (work%col(i) > ptol) then
               k = k + 1
               work%cand(k) = i
            end if
         end do
         if (k == 0) then
            status = lcp_ray
            return
         end if
         call select_row(work, nn, k, .true., r)
      end do
   end subroutine lemke_core

   !> Leaving row among the candidate rows work%cand(1:k) (work%col > 0 there): the
   !> lexicographic minimum of (rhs_i, Binv(i, :)) / col_i, Binv being the first nn
   !> columns of the tableau; z0 leaves whenever its row ties at the minimum ratio.
   pure subroutine select_row(work, nn, k, prefer_z0, r)
      type(lcp_work), intent(inout) :: work
      integer, intent(in) :: nn, k
      logical, intent(in) :: prefer_z0
      integer, intent(out) :: r
      integer :: c, kk, kept, i, j
      real(dp) :: vmin, vtol, v, best

      kk = k
      j = 2*nn + 2                     ! the rhs, then the columns of the basis inverse
      do
         vmin = huge(1.0_dp)
         do c = 1, kk
            i = work%cand(c)
            vmin = min(vmin, work%tab(i, j)/work%col(i))
         end do
         vtol = tie_rel*max(1.0_dp, abs(vmin))
         kept = 0
         do c = 1, kk
            i = work%cand(c)
            if (work%tab(i, j)/work%col(i) <= vmin + vtol) then
               kept = kept + 1
               work%cand(kept) = i
            end if
         end do
         kk = kept
         if (j == 2*nn + 2 .and. prefer_z0) then
            do c = 1, kk
               if (work%basis(work%cand(c)) == 2*nn + 1) then
                  r = work%cand(c)
                  return
               end if
            end do
         end if
         if (kk == 1) exit
         if (j == 2*nn + 2) then
            j = 1
         else
            j = j + 1
         end if
         if (j > nn) exit
      end do
      ! ties left only by round-off: the largest pivot
      r = work%cand(1)
      best = work%col(r)
      do c = 2, kk
         v = work%col(work%cand(c))
         if (v > best) then
            best = v
            r = work%cand(c)
         end if
      end do
   end subroutine select_row

   !> Pivot the tableau on row r, column e.
   pure subroutine pivot(work, nn, r, e)
      type(lcp_work), intent(inout) :: work
      integer, intent(in) :: nn, r, e
      integer :: i, j
      real(dp) :: p, f

      do i = 1, nn
         work%col(i) = work%tab(i, e)
      end do
      p = work%col(r)
      do j = 1, 2*nn + 2
         f = work%tab(r, j)
         if (f == 0.0_dp) cycle
         f = f/p
         do i = 1, nn
            work%tab(i, j) = work%tab(i, j) - work%col(i)*f
         end do
         work%tab(r, j) = f
      end do
      do i = 1, nn
         work%tab(i, e) = 0.0_dp
      end do
      work%tab(r, e) = 1.0_dp
   end subroutine pivot

   !> D = diag(1/sqrt(M_ii)) where M_ii > 0 (else 1), in work%dsc.
   pure subroutine unit_scaling(work, m, n)
      type(lcp_work), intent(inout) :: work
      real(dp), intent(in) :: m(:, :)
      integer, intent(in) :: n
      integer :: i

      do i = 1, n
         work%dsc(i) = unit_scale(m(i, i))
      end do
   end subroutine unit_scaling

   !> 1/sqrt(M_ii) for a positive diagonal entry M_ii, else 1: the symmetric scaling D M D
   !> that gives M a unit diagonal.
   elemental real(dp) function unit_scale(mii) result(d)
      real(dp), intent(in) :: mii

      d = 1.0_dp
      if (mii > 0.0_dp) d = 1.0_dp/sqrt(mii)
   end function unit_scale

   !> Clip Lemke's z (work%zb) into the bounds, and polish it: solve the final pattern's
   !> system again on the original data; keep whichever has the smaller residual.
   pure subroutine finish(work, m, q, n, box, z, w, info)
      type(lcp_work), intent(inout) :: work
      real(dp), intent(in) :: m(:, :), q(:)
      integer, intent(in) :: n
      logical, intent(in) :: box
      real(dp), intent(out) :: z(:), w(:)
      type(lcp_info), intent(inout) :: info
      real(dp) :: r1, r2
      integer :: flag

      z = work%zb(1:n)
      call clip(z, box, work%blo(1:n), work%bhi(1:n))
      call affine(m, z, q, w)
      r1 = residual_core(m, q, z, w, box, work%blo(1:n), work%bhi(1:n))
      if (r1 > 0.0_dp) then
         call pattern_solve(work, m, q, n, flag)
         if (flag == 0) then
            call clip(work%zt(1:n), box, work%blo(1:n), work%bhi(1:n))
            call affine(m, work%zt(1:n), q, work%wt(1:n))
            r2 = residual_core(m, q, work%zt(1:n), work%wt(1:n), box, work%blo(1:n), work%bhi(1:n))
            if (r2 < r1) then
               z = work%zt(1:n)
               w = work%wt(1:n)
               r1 = r2
            end if
         end if
      end if
      call judge(r1, work%tol, lcp_inaccurate, info)
   end subroutine finish

   !> The z of one pattern (work%state): variables at a bound take it, the free ones solve
   !> M_FF z_F = -(q_F + M_F,fixed z_fixed) (scaled, complete pivoting, one refinement step).
   !> flag 0: nonsingular; 1: singular but consistent (basic solution); 2: inconsistent.
   !> The result is in work%zt.
   pure subroutine pattern_solve(work, m, q, n, flag)
      type(lcp_work), intent(inout) :: work
      real(dp), intent(in) :: m(:, :), q(:)
      integer, intent(in) :: n
      integer, intent(out) :: flag
      integer :: i, j, a, b, k, rank
      real(dp) :: acc
      logical :: consistent

      k = 0
      do i = 1, n
         select case (work%state(i))
         case (at_lo)
            work%zt(i) = work%blo(i)
         case (at_hi)
            work%zt(i) = work%bhi(i)
         case default
            k = k + 1
            work%idx(k) = i
            work%zt(i) = 0.0_dp
         end select
      end do
      flag = 0
      if (k == 0) return
      do a = 1, k
         i = work%idx(a)
         work%ds(a) = unit_scale(m(i, i))
      end do
      do a = 1, k
         i = work%idx(a)
         acc = -q(i)
         do j = 1, n
            if (work%state(j) /= free .and. work%zt(j) /= 0.0_dp) acc = acc - m(i, j)*work%zt(j)
         end do
         work%rv(a) = work%ds(a)*acc
         work%r0(a) = work%rv(a)
         do b = 1, k
            work%amat(a, b) = work%ds(a)*m(i, work%idx(b))*work%ds(b)
            work%a0(a, b) = work%amat(a, b)
         end do
      end do
      call ge_factor(work%amat, k, rank, work%ip, work%jp)
      call ge_solve(work%amat, k, rank, work%ip, work%jp, work%rv, work%xv, consistent)
      if (.not. consistent) then
         flag = 2
         return
      end if
      if (rank == k) then
         ! one step of iterative refinement on the scaled system
         do a = 1, k
            acc = work%r0(a)
            do b = 1, k
               acc = acc - work%a0(a, b)*work%xv(b)
            end do
            work%rv(a) = acc
         end do
         call ge_solve(work%amat, k, rank, work%ip, work%jp, work%rv, work%dx, consistent)
         do a = 1, k
            work%xv(a) = work%xv(a) + work%dx(a)
         end do
      else
         flag = 1
      end if
      do a = 1, k
         work%zt(work%idx(a)) = work%ds(a)*work%xv(a)
      end do
   end subroutine pattern_solve

   !> LU factorization with complete pivoting of a(1:k, 1:k) in place, stopping at the
   !> numerical rank (pivot <= rank_rel max |a|): P a Q = L U.
   pure subroutine ge_factor(a, k, rank, ip, jp)
      real(dp), intent(inout) :: a(:, :)
      integer, intent(in) :: k
      integer, intent(out) :: rank
      integer, intent(out) :: ip(:), jp(:)
      integer :: s, i, j, pi, pj
      real(dp) :: amax0, big, t

      amax0 = 0.0_dp
      do j = 1, k
         do i = 1, k
            amax0 = max(amax0, abs(a(i, j)))
         end do
      end do
      do s = 1, k
         ip(s) = s
         jp(s) = s
      end do
      rank = 0
      do s = 1, k
         big = 0.0_dp
         pi = s
         pj = s
         do j = s, k
            do i = s, k
               if (abs(a(i, j)) > big) then
                  big = abs(a(i, j))
                  pi = i
                  pj = j
               end if
            end do
         end do
         if (big <= rank_rel*amax0 .or. big == 0.0_dp) exit
         rank = s
         ip(s) = pi
         jp(s) = pj
         if (pi /= s) then
            do j = 1, k
               t = a(s, j); a(s, j) = a(pi, j); a(pi, j) = t
            end do
         end if
         if (pj /= s) then
            do i = 1, k
               t = a(i, s); a(i, s) = a(i, pj); a(i, pj) = t
            end do
         end if
         do i = s + 1, k
            a(i, s) = a(i, s)/a(s, s)
         end do
         do j = s + 1, k
            t = a(s, j)
            if (t == 0.0_dp) cycle
            do i = s + 1, k
               a(i, j) = a(i, j) - a(i, s)*t
            end do
         end do
      end do
   end subroutine ge_factor

   !> Solve with the factors of ge_factor: x = Q U^-1 L^-1 P b, the components beyond the
   !> rank set to zero; consistent is false when the rows beyond the rank do not vanish.
   pure subroutine ge_solve(a, k, rank, ip, jp, b, x, consistent)
      real(dp), intent(in) :: a(:, :)
      integer, intent(in) :: k, rank
      integer, intent(in) :: ip(:), jp(:)
      real(dp), intent(inout) :: b(:)
      real(dp), intent(out) :: x(:)
      logical, intent(out) :: consistent
      integer :: s, i, j
      real(dp) :: t, bmax

      bmax = 0.0_dp
      do i = 1, k
         bmax = max(bmax, abs(b(i)))
      end do
      do s = 1, rank
         if (ip(s) /= s) then
            t = b(s); b(s) = b(ip(s)); b(ip(s)) = t
         end if
      end do
      do s = 1, rank
         t = b(s)
         if (t == 0.0_dp) cycle
         do i = s + 1, k
            b(i) = b(i) - a(i, s)*t
         end do
      end do
      consistent = .true.
      do i = rank + 1, k
         if (abs(b(i)) > cons_rel*bmax) consistent = .false.
      end do
      do i = rank + 1, k
         x(i) = 0.0_dp
      end do
      do s = rank, 1, -1
         t = b(s)
         do j = s + 1, rank
            t = t - a(s, j)*x(j)
         end do
         x(s) = t/a(s, s)
      end do
      do s = rank, 1, -1
         if (jp(s) /= s) then
            t = x(s); x(s) = x(jp(s)); x(jp(s)) = t
         end if
      end do
   end subroutine ge_solve

   !> Projected Gauss-Seidel on the bounds in work%blo/bhi (standard: lo = 0, no upper).
   pure subroutine pgs_core(work, m, q, box, z, w, info)
      type(lcp_work), intent(in) :: work
      real(dp), intent(in) :: m(:, :), q(:)
      logical, intent(in) :: box
      real(dp), intent(inout) :: z(:)
      real(dp), intent(out) :: w(:)
      type(lcp_info), intent(inout) :: info
      integer :: n, i, k, sweep
      real(dp) :: zi, d, res

      n = size(q)
      do i = 1, n
         if (.not. ieee_is_finite(z(i))) z(i) = 0.0_dp
      end do
      call clip(z, box, work%blo(1:n), work%bhi(1:n))
      call affine(m, z, q, w)
      res = residual_core(m, q, z, w, box, work%blo(1:n), work%bhi(1:n))
      sweep = 0
      do while (res > work%pgs_tol .and. sweep < work%pgs_max_sweeps)
         sweep = sweep + 1
         do i = 1, n
            zi = max(z(i) - w(i)/m(i, i), work%blo(i))
            if (box) zi = min(zi, work%bhi(i))
            d = zi - z(i)
            if (d == 0.0_dp) cycle
            z(i) = zi
            do k = 1, n
               w(k) = w(k) + m(k, i)*d
            end do
         end do
         call affine(m, z, q, w)
         res = residual_core(m, q, z, w, box, work%blo(1:n), work%bhi(1:n))
      end do
      info%iterations = sweep
      call judge(res, work%pgs_tol, lcp_not_converged, info)
   end subroutine pgs_core

   !> The residual of the returned z and the status it earns: lcp_solved within tol, else
   !> the status given.
   pure subroutine judge(res, tol, failed, info)
      real(dp), intent(in) :: res
      real(dp), intent(in) :: tol
      integer, intent(in) :: failed
      type(lcp_info), intent(inout) :: info

      info%residual = res
      if (res <= tol) then
         info%status = lcp_solved
      else
         info%status = failed
      end if
   end subroutine judge

   !> w = M z + q.
   pure subroutine affine(m, z, q, w)
      real(dp), intent(in) :: m(:, :), z(:), q(:)
      real(dp), intent(out) :: w(:)
      integer :: i, j

      do i = 1, size(q)
         w(i) = q(i)
      end do
      do j = 1, size(q)
         if (z(j) == 0.0_dp) cycle
         do i = 1, size(q)
            w(i) = w(i) + m(i, j)*z(j)
         end do
      end do
   end subroutine affine

   !> Clip z into [lo, hi] (standard LCP: z >= 0).
   pure subroutine clip(z, box, lo, hi)
      real(dp), intent(inout) :: z(:)
      logical, intent(in) :: box
      real(dp), intent(in) :: lo(:), hi(:)
      integer :: i

      do i = 1, size(z)
         if (box) then
            z(i) = min(max(z(i), lo(i)), hi(i))
         else
            z(i) = max(z(i), 0.0_dp)
         end if
      end do
   end subroutine clip

   !> The relative residual of lcp_residual / box_lcp_residual (lo, hi unused if not box).
   pure function residual_core(m, q, z, w, box, lo, hi) result(res)
      real(dp), intent(in) :: m(:, :), q(:), z(:), w(:)
      logical, intent(in) :: box
      real(dp), intent(in) :: lo(:), hi(:)
      real(dp) :: res
      real(dp) :: zs, ws, eq, s, t
      integer :: n, i, j

      n = size(q)
      zs = 0.0_dp
      do i = 1, n
         zs = max(zs, abs(z(i)))
         if (box) zs = max(zs, abs(lo(i)), abs(hi(i)))
      end do
      if (zs == 0.0_dp) zs = 1.0_dp
      ws = 0.0_dp
      eq = 0.0_dp
      do i = 1, n
         s = abs(q(i))
         t = q(i)
         do j = 1, n
            s = s + abs(m(i, j))*zs
            t = t + m(i, j)*z(j)
         end do
         ws = max(ws, s)
         eq = max(eq, abs(w(i) - t))
      end do
      if (ws == 0.0_dp) ws = 1.0_dp
      res = eq/ws
      do i = 1, n
         t = z(i) - w(i)*(zs/ws)
         if (box) then
            t = min(max(t, lo(i)), hi(i))
         else
            t = max(t, 0.0_dp)
         end if
         res = max(res, abs(z(i) - t)/zs)
      end do
      if (.not. ieee_is_finite(res)) res = huge(1.0_dp)
   end function residual_core

   !> Entry of every solver: record the method, check the data (PGS: the diagonal too;
   !> enumeration: its size limit) and put the bounds in the workspace (standard LCP: 0 and
   !> no upper bound). On return info%status is lcp_solved if the solver may run; if not,
   !> z = w = 0.
   pure subroutine enter(work, method, m, q, z, w, info, lo, hi)
      type(lcp_work), intent(inout) :: work
      integer, intent(in) :: method
      real(dp), intent(in) :: m(:, :), q(:)
      real(dp), intent(inout) :: z(:), w(:)
      type(lcp_info), intent(inout) :: info
      real(dp), intent(in), optional :: lo(:), hi(:)
      integer :: n, limit

      info%method = method
      call check_input(work, m, q, z, w, method /= lcp_method_pgs, info%status, lo, hi)
      if (info%status == lcp_solved .and. method == lcp_method_pgs) call check_diagonal(m, info%status)
      if (info%status == lcp_solved .and. method == lcp_method_enumeration) then
         limit = work%enum_max
         if (present(lo)) limit = work%box_enum_max
         if (size(q) > min(limit, max_enum_bits)) info%status = lcp_too_large
      end if
      if (info%status /= lcp_solved) then
         call clear(z, w)
         return
      end if
      n = size(q)
      if (present(lo) .and. present(hi)) then
         work%blo(1:n) = lo
         work%bhi(1:n) = hi
      else
         work%blo(1:n) = 0.0_dp
         work%bhi(1:n) = huge(1.0_dp)
      end if
   end subroutine enter

   !> Try the pattern in work%state: its z clipped into the bounds, w = M z + q and the
   !> residual res; flag as pattern_solve (2: no z, res = huge).
   pure subroutine try_pattern(work, m, q, n, box, z, w, flag, res)
      type(lcp_work), intent(inout) :: work
      real(dp), intent(in) :: m(:, :), q(:)
      integer, intent(in) :: n
      logical, intent(in) :: box
      real(dp), intent(out) :: z(:), w(:)
      integer, intent(out) :: flag
      real(dp), intent(out) :: res

      res = huge(1.0_dp)
      call pattern_solve(work, m, q, n, flag)
      if (flag == 2) return
      z = work%zt(1:n)
      call clip(z, box, work%blo(1:n), work%bhi(1:n))
      call affine(m, z, q, w)
      res = residual_core(m, q, z, w, box, work%blo(1:n), work%bhi(1:n))
   end subroutine try_pattern

   !> Sizes, finiteness and bounds of the data; status lcp_solved when all is well.
   pure subroutine check_input(work, m, q, z, w, pivoting, status, lo, hi)
      type(lcp_work), intent(in) :: work
      real(dp), intent(in) :: m(:, :), q(:), z(:), w(:)
      logical, intent(in) :: pivoting
      integer, intent(out) :: status
      real(dp), intent(in), optional :: lo(:), hi(:)
      integer :: n, i, j

      status = lcp_bad_input
      n = size(q)
      if (work%nmax == 0 .or. n < 1 .or. n > work%nmax) return
      if (pivoting .and. n > work%pmax) return
      if (size(m, 1) /= n .or. size(m, 2) /= n .or. size(z) /= n .or. size(w) /= n) return
      do j = 1, n
         do i = 1, n
            if (.not. ieee_is_finite(m(i, j))) return
         end do
         if (.not. ieee_is_finite(q(j))) return
      end do
      if (present(lo) .and. present(hi)) then
         if (size(lo) /= n .or. size(hi) /= n) return
         do i = 1, n
            if (.not. (ieee_is_finite(lo(i)) .and. ieee_is_finite(hi(i)))) return
            if (lo(i) > hi(i)) return
         end do
      end if
      status = lcp_solved
   end subroutine check_input

   !> PGS divides by M_ii: it must be positive.
   pure subroutine check_diagonal(m, status)
      real(dp), intent(in) :: m(:, :)
      integer, intent(inout) :: status
      integer :: i

      do i = 1, size(m, 1)
         if (.not. (m(i, i) > 0.0_dp)) status = lcp_bad_input
      end do
   end subroutine check_diagonal

   pure subroutine clear(z, w)
      real(dp), intent(out) :: z(:), w(:)
      z = 0.0_dp
      w = 0.0_dp
   end subroutine clear

end module fd_lcp
