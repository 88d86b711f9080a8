!> The effective stiffness of a structure with friction devices, stored and factored the way
!> its graph allows, and kept factored as devices change phase:
!>
!>   K^ = K + c1 C + c0 M + sum_d kd_d b_d b_d'
!>
!> with b_d device d's direction over the DOFs (a few terms: e_i - e_j for a device between
!> two nodes, e_i for one on the table).
!>
!> K (springs) and C (a0 M + a1 K + dashpots) are stored once, in a reverse Cuthill-McKee
!> ordering of the graph of springs, dashpots and devices, as symmetric band matrices
!> (memory n (bandwidth + 1) each); K^ is factored by LAPACK's banded Cholesky (dpbtrf). A
!> small system (n <= spd_dense_max_n) is stored dense and factored by dpotrf instead, where
!> that is faster.
!>
!> A change of one device's kd is a rank-one change of K^: its factor is updated (kd grew)
!> or downdated (kd shrank) in O((n - first column) * bandwidth) operations, with the
!> mixed hyperbolic rotations of Chambers / Bojanczyk et al., stopped once the rest of the
!> change is below rounding (in a K^ dominated by inertia, after a few columns: the cost of
!> an update then does not grow with n). When several devices change
!> together, the factor is recomputed from the first changed column instead if that costs
!> fewer operations. A per-column estimate of the backward error that updates add (with
!> respect to a fresh factor) is kept; a downdate whose pivot collapses (positive
!> definiteness lost to round-off, or the error budget exceeded) is abandoned and the matrix
!> refactored, counted in the statistics. After spd_setup nothing allocates.
module fd_banded
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use, intrinsic :: iso_fortran_env, only: int64
   use fd_kinds, only: dp
   use fd_lapack, only: dpbtf2, dpbtrf, dpbtrs, dpotf2, dpotrf, dsbmv, dsymv, dsyrk, dtrsv
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real, stat_no_memory
   use fd_rcm, only: rcm_order, graph_bandwidth
   implicit none
   private

   public :: spd_system, spd_stats, spd_setup, spd_copy, spd_factor, spd_update_device, spd_update_devices
   public :: spd_solve, spd_k_matvec, spd_c_matvec, spd_kc_matvec
   public :: spd_size, spd_bandwidth, spd_is_dense, spd_device_kd, spd_error_estimate
   public :: spd_auto, spd_dense, spd_banded, spd_dense_max_n, spd_choose, spd_rank_one, spd_refactor
   public :: band_potf2

   integer, parameter :: spd_auto = 0    !! storage chosen by size and bandwidth
   integer, parameter :: spd_dense = 1   !! dense storage, dpotrf
   integer, parameter :: spd_banded = 2  !! RCM ordering, band storage, dpbtrf

   integer, parameter :: spd_choose = 0    !! device changes: by operation count
   integer, parameter :: spd_rank_one = 1  !! device changes: always rank-one modifications
   integer, parameter :: spd_refactor = 2  !! device changes: always refactor from the first column

   !> Largest n stored dense by spd_auto: the measured crossover of a step's solve and two
   !> products (bash bench/banded.sh small; banded is faster from n = 9 on).
   integer, parameter :: spd_dense_max_n = 8

   !> Backward error a single rank-one modification adds, relative to the pivot it touches.
   real(dp), parameter :: unit_error = 2.0_dp*epsilon(1.0_dp)
   !> Update entries below this times their pivot are dropped (tau^2 = eps/4).
   real(dp), parameter :: truncate_tol = 0.5_dp*sqrt(epsilon(1.0_dp))
   !> Band up to which the solve is this module's loops (band_solve), not dpbtrs.
   integer, parameter :: narrow_band = 8
   !> Order (dense) or band up to which the unblocked LAPACK factorizations are called.
   integer, parameter :: unblocked_max = 64
   !> A pivot^2 below this times (band + 1) times its diagonal is rounding noise.
   real(dp), parameter :: singular_tol = 4.0_dp*epsilon(1.0_dp)
   !> Default budget of that estimated error before a refactorization.
   real(dp), parameter :: default_budget = 1.0e-12_dp
   !> Cost model, in flop equivalents, measured by `bash bench/banded.sh calibrate` (about
   !> 0.37 ns each): a rank-one modification costs w_update + band per column touched (it is
   !> bound by the latency of a square root and two divisions, not by its 4 band flops), a
   !> refactorization w_factor + band^2 + 2 band per column (dpbtf2's two BLAS calls). A band
   !> up to narrow_band is now refactored by band_potf2, without those calls, so this prices
   !> its refactorization high; the weights are kept as measured, since changing them changes
   !> which of the two is chosen, and with it the factor's last bits and the counts.
   real(dp), parameter :: w_update = 64.0_dp, w_factor = 90.0_dp

   !> What the factor has cost so far; the caller may report it.
   type :: spd_stats
      integer :: factorizations = 0 !! full factorizations (spd_factor, fallbacks, refreshes)
      integer :: partial = 0        !! refactorizations from the first changed column
      integer :: updates = 0        !! rank-one updates made (a device stiffness grew)
      integer :: downdates = 0      !! rank-one downdates made (a device stiffness shrank)
      integer :: fallbacks = 0      !! downdates abandoned (pivot lost to round-off): refactored
      integer :: refreshes = 0      !! modifications that would exceed the error budget: refactored
      integer(int64) :: update_columns = 0 !! columns touched by the rank-one modifications
   end type spd_stats

   !> The system: structure, storage, factor and work space. Set up by spd_setup.
   type :: spd_system
      type(spd_stats) :: stats                        !! counts of the work done
      integer, private :: n = 0                       !! number of DOFs
      integer, private :: nd = 0                      !! number of devices
      integer, private :: kb = 0                      !! half-bandwidth (n - 1 when dense)
      integer, private :: ld = 0                      !! leading dimension of the storage
      integer, private :: sj = 0, off = 0             !! U(i, j) is stored at i + j sj + off
      logical, private :: dense = .false.             !! dense storage (else band)
      integer, private :: method = spd_choose         !! how device changes are made
      logical, private :: factored = .false.          !! fac holds the factor of K^
      real(dp), private :: c0 = 0.0_dp, c1 = 0.0_dp  !! coefficients of M and C in K^
      real(dp), private :: a0 = 0.0_dp, a1 = 0.0_dp  !! C = a0 M + a1 K (+ dashpots)
      logical, private :: rayleigh_c = .true.         !! C = a0 M + a1 K exactly (no dashpots)
      real(dp), private :: budget = default_budget    !! allowed estimated update error
      real(dp), private :: span = huge(1.0_dp)        !! running mean of columns per update
      integer, allocatable, private :: perm(:)        !! new -> old DOF
      integer, allocatable, private :: inv(:)         !! old -> new DOF
      integer, allocatable, private :: dlo(:), dhi(:) !! first and last column of each device (new
                                                      !! order); dhi = 0 for a one-term device
      integer, allocatable, private :: dptr(:)        !! start of each device's terms
      integer, allocatable, private :: dcol(:)        !! column of each term (new order)
      real(dp), allocatable, private :: dval(:)       !! coefficient of each term, signed so that
                                                      !! the one in column dlo is positive
      integer, allocatable, private :: dorder(:)      !! devices by decreasing last column
      real(dp), allocatable, private :: mass(:)       !! masses (new order)
      real(dp), allocatable, private :: kmat(:)       !! K, upper triangle, storage layout
      real(dp), allocatable, private :: cmat(:)       !! C, upper triangle, storage layout
      real(dp), allocatable, private :: fac(:)        !! Cholesky factor U of K^ = U' U
      real(dp), allocatable, private :: kd(:)         !! device stiffness in the factor
      real(dp), allocatable, private :: errcol(:)     !! estimated update error per column
      real(dp), allocatable, private :: w1(:), w2(:)  !! work vectors (permutations)
      real(dp), allocatable, private :: xv(:)         !! update vector, zero between calls
      real(dp), allocatable, private :: rdiag(:)      !! 1 / U(j, j) (the small dense solve)
   end type spd_system

contains

   !> Set up the system: graph, ordering, storage, K and C. Allocates everything the
   !> other procedures use; the factor is made by spd_factor.
   subroutine spd_setup(sys, mass, spring_i, spring_j, spring_k, dev_ptr, dev_dof, dev_coef, error, &
                        a0, a1, dashpot_i, dashpot_j, dashpot_c, path, budget, method, kx_i, kx_j, kx_v)
      type(spd_system), intent(out) :: sys       !! the system
      real(dp), intent(in) :: mass(:)            !! masses [kg], one per DOF (n = size)
      integer, intent(in) :: spring_i(:)         !! first node of each spring (0..n, 0 = table)
      integer, intent(in) :: spring_j(:)         !! second node of each spring (0..n)
      real(dp), intent(in) :: spring_k(:)        !! spring stiffness [N/m], >= 0
      integer, intent(in) :: dev_ptr(:)          !! start of each device's terms (devices + 1)
      integer, intent(in) :: dev_dof(:)          !! DOF of each term (1..n)
      real(dp), intent(in) :: dev_coef(:)        !! coefficient of each term (finite, not 0)
      type(error_type), allocatable, intent(out) :: error !! invalid input
      real(dp), intent(in), optional :: a0       !! C = a0 M + ... [1/s], default 0
      real(dp), intent(in), optional :: a1       !! C = ... + a1 K + ... [s], default 0
      integer, intent(in), optional :: dashpot_i(:)  !! first node of each dashpot (0..n)
      integer, intent(in), optional :: dashpot_j(:)  !! second node of each dashpot (0..n)
      real(dp), intent(in), optional :: dashpot_c(:) !! dashpot coefficient [N s/m], >= 0
      integer, intent(in), optional :: path      !! spd_auto (default), spd_dense or spd_banded
      real(dp), intent(in), optional :: budget   !! allowed estimated update error, default 1e-12
      integer, intent(in), optional :: method    !! spd_choose (default), spd_rank_one, spd_refactor
      integer, intent(in), optional :: kx_i(:)   !! more stiffness K_x: row of each entry (1..n)
      integer, intent(in), optional :: kx_j(:)   !! its column (kx_i <= kx_j)
      real(dp), intent(in), optional :: kx_v(:)  !! its value
      integer, allocatable :: di(:), dj(:), xi(:), xj(:), gi(:), gj(:)
      real(dp), allocatable :: dc(:), xv(:)
      real(dp) :: ca0, ca1
      integer :: n, nd, i, kbw, mode, stat

      n = size(mass)
      nd = size(dev_ptr) - 1
      ca0 = 0.0_dp
      ca1 = 0.0_dp
      if (present(a0)) ca0 = a0
      if (present(a1)) ca1 = a1
      mode = spd_auto
      if (present(path)) mode = path
      call optional_entries("dashpot_i, dashpot_j and dashpot_c", di, dj, dc, error, dashpot_i, dashpot_j, dashpot_c)
      if (allocated(error)) return
      call optional_entries("kx_i, kx_j and kx_v", xi, xj, xv, error, kx_i, kx_j, kx_v)
      if (allocated(error)) return
      call check_entries(xi, xj, xv, n, error)
      if (allocated(error)) return
      call check_setup(mass, spring_i, spring_j, spring_k, dev_ptr, dev_dof, dev_coef, di, dj, dc, ca0, ca1, &
                       mode, error)
      if (allocated(error)) return
      if (present(method)) then
         if (method /= spd_choose .and. method /= spd_rank_one .and. method /= spd_refactor) then
            call fatal_error(error, "spd_setup: method = "//trim(fmt_int(method))//" is not spd_choose, &
                             &spd_rank_one or spd_refactor")
            return
         end if
         sys%method = method
      end if
      if (present(budget)) then
         if (.not. (budget > 0.0_dp)) then
            call fatal_error(error, "spd_setup: budget = "//trim(fmt_real(budget))//" must be > 0")
            return
         end if
         sys%budget = budget
      end if

      ! the graph's edges: the springs and the entries of K_x off the diagonal
      gi = [spring_i, pack(xi, xi /= xj)]
      gj = [spring_j, pack(xj, xi /= xj)]
      call order_graph(sys, n, gi, gj, dev_ptr, dev_dof, di, dj, kbw)
      if (mode == spd_auto) then
         ! dense where it is faster: a few DOFs (a band nearly as wide as the matrix is no
         ! slower than dense storage: bench/banded.sh wide)
         mode = spd_banded
         if (n <= spd_dense_max_n) mode = spd_dense
      end if
      sys%n = n
      sys%nd = nd
      sys%dense = mode == spd_dense
      if (sys%dense) then
         sys%perm = [(i, i=1, n)]
         sys%inv = sys%perm
         sys%kb = n - 1
         sys%ld = n
         sys%sj = n
         sys%off = -n
      else
         sys%kb = kbw
         sys%ld = kbw + 1
         sys%sj = kbw
         sys%off = 0
      end if

      if (int(sys%ld, int64)*n > int(huge(n), int64)) then
         call fatal_error(error, "not enough memory for the effective stiffness of "//trim(fmt_int(n))// &
                          " DOFs of half-bandwidth "//trim(fmt_int(sys%kb))//": "// &
                          trim(fmt_real(real(sys%ld, dp)*n))//" values each, more than one array may hold", &
                          stat_no_memory)
         return
      end if
      allocate (sys%mass(n), sys%kmat(sys%ld*n), sys%cmat(sys%ld*n), sys%fac(sys%ld*n), sys%kd(nd), &
                sys%errcol(n), sys%w1(n), sys%w2(n), sys%xv(n), sys%rdiag(n), sys%dlo(nd), sys%dhi(nd), &
                sys%dorder(nd), sys%dptr(nd + 1), sys%dcol(dev_ptr(nd + 1) - 1), &
                sys%dval(dev_ptr(nd + 1) - 1), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the effective stiffness of "//trim(fmt_int(n))// &
                          " DOFs of half-bandwidth "//trim(fmt_int(sys%kb))//" (3 x "// &
                          trim(fmt_real(8.0_dp*real(sys%ld, dp)*n/2.0_dp**20))//" MiB)", stat_no_memory)
         return
      end if
      call assemble(sys, mass, spring_i, spring_j, spring_k, di, dj, dc, ca0, ca1, xi, xj, xv)
      call order_devices(sys, dev_ptr, dev_dof, dev_coef)
      call sort_devices(sys)
   end subroutine spd_setup

   !> The input of spd_setup checked: masses, springs, devices, dashpots, C's factors, path.
   subroutine check_setup(mass, spring_i, spring_j, spring_k, dev_ptr, dev_dof, dev_coef, di, dj, dc, ca0, ca1, &
                          mode, error)
      real(dp), intent(in) :: mass(:), spring_k(:), dev_coef(:), dc(:), ca0, ca1
      integer, intent(in) :: spring_i(:), spring_j(:), dev_ptr(:), dev_dof(:), di(:), dj(:), mode
      type(error_type), allocatable, intent(out) :: error
      integer :: n, ns, nc, i

      n = size(mass)
      ns = size(spring_i)
      nc = size(di)
      if (n < 1) then
         call fatal_error(error, "spd_setup: the structure has no DOF (size(mass) = 0)")
         return
      end if
      do i = 1, n
         if (.not. (mass(i) > 0.0_dp .and. ieee_is_finite(mass(i)))) then
            call fatal_error(error, "spd_setup: mass("//trim(fmt_int(i))//") = "//trim(fmt_real(mass(i)))// &
                             " must be finite and > 0")
            return
         end if
      end do
      if (size(spring_j) /= ns .or. size(spring_k) /= ns) then
         call fatal_error(error, "spd_setup: spring_i, spring_j and spring_k differ in size")
         return
      end if
      call check_devices(dev_ptr, dev_dof, dev_coef, n, error)
      if (allocated(error)) return
      if (size(dj) /= nc .or. size(dc) /= nc) then
         call fatal_error(error, "spd_setup: dashpot_i, dashpot_j and dashpot_c differ in size")
         return
      end if
      call check_links("spring", spring_i, spring_j, spring_k, n, error)
      if (allocated(error)) return
      call check_links("dashpot", di, dj, dc, n, error)
      if (allocated(error)) return
      if (.not. (ca0 >= 0.0_dp .and. ieee_is_finite(ca0))) then
         call fatal_error(error, "spd_setup: a0 = "//trim(fmt_real(ca0))//" must be finite and >= 0")
         return
      end if
      if (.not. (ca1 >= 0.0_dp .and. ieee_is_finite(ca1))) then
         call fatal_error(error, "spd_setup: a1 = "//trim(fmt_real(ca1))//" must be finite and >= 0")
         return
      end if
      if (mode /= spd_auto .and. mode /= spd_dense .and. mode /= spd_banded) then
         call fatal_error(error, "spd_setup: path = "//trim(fmt_int(mode))//" is not spd_auto, spd_dense &
                          &or spd_banded")
         return
      end if
   end subroutine check_setup

   !> The graph of springs, devices and dashpots, its reverse Cuthill-McKee order (perm,
   !> inv) and the half-bandwidth kbw in that order.
   subroutine order_graph(sys, n, spring_i, spring_j, dev_ptr, dev_dof, di, dj, kbw)
      type(spd_system), intent(inout) :: sys
      integer, intent(in) :: n, spring_i(:), spring_j(:), dev_ptr(:), dev_dof(:), di(:), dj(:)
      integer, intent(out) :: kbw
      integer, allocatable :: ei(:), ej(:)
      integer :: ns, nd, nc, ne, d, i

      ns = size(spring_i)
      nd = size(dev_ptr) - 1
      nc = size(di)
      ! the graph: springs and dashpots between two DOFs, each device a star from its first
      ! term (its edge to the table, node 0, when it has one term)
      ne = ns + (dev_ptr(nd + 1) - 1) + nc
      allocate (ei(ne), ej(ne))
      ne = ns
      ei(1:ns) = spring_i
      ej(1:ns) = spring_j
      do d = 1, nd
         ne = ne + 1
         ei(ne) = dev_dof(dev_ptr(d))
         ej(ne) = 0
         if (dev_ptr(d + 1) - dev_ptr(d) > 1) ej(ne) = dev_dof(dev_ptr(d) + 1)
         do i = dev_ptr(d) + 2, dev_ptr(d + 1) - 1
            ne = ne + 1
            ei(ne) = dev_dof(dev_ptr(d))
            ej(ne) = dev_dof(i)
         end do
      end do
      ei(ne + 1:ne + nc) = di
      ej(ne + 1:ne + nc) = dj
      ne = ne + nc
      allocate (sys%perm(n), sys%inv(n))
      call rcm_order(n, ei(1:ne), ej(1:ne), sys%perm)
      do i = 1, n
         sys%inv(sys%perm(i)) = i
      end do
      kbw = graph_bandwidth(ei(1:ne), ej(1:ne), sys%inv)
      ! a device of three or more terms spans more than its star's edges
      do d = 1, nd
         if (dev_ptr(d + 1) - dev_ptr(d) < 3) cycle
         kbw = max(kbw, maxval(sys%inv(dev_dof(dev_ptr(d):dev_ptr(d + 1) - 1))) - &
                   minval(sys%inv(dev_dof(dev_ptr(d):dev_ptr(d + 1) - 1))))
      end do
   end subroutine order_graph

   !> K (springs) and C = a0 M + a1 K + dashpots in the storage, the rest zeroed.
   subroutine assemble(sys, mass, spring_i, spring_j, spring_k, di, dj, dc, ca0, ca1, xi, xj, xv)
      type(spd_system), intent(inout) :: sys
      real(dp), intent(in) :: mass(:), spring_k(:), dc(:), ca0, ca1, xv(:)
      integer, intent(in) :: spring_i(:), spring_j(:), di(:), dj(:), xi(:), xj(:)
      integer :: i, a, b, n

      n = sys%n
      sys%rdiag = 0.0_dp
      sys%mass = mass(sys%perm)
      sys%kmat = 0.0_dp
      sys%cmat = 0.0_dp
      sys%fac = 0.0_dp
      sys%kd = 0.0_dp
      sys%errcol = 0.0_dp
      sys%w1 = 0.0_dp
      sys%w2 = 0.0_dp
      sys%xv = 0.0_dp
      do i = 1, size(spring_i)
         call add_link(sys, sys%kmat, spring_i(i), spring_j(i), spring_k(i))
      end do
      do i = 1, size(xi)
         a = min(sys%inv(xi(i)), sys%inv(xj(i)))
         b = max(sys%inv(xi(i)), sys%inv(xj(i)))
         sys%kmat(idx(sys, a, b)) = sys%kmat(idx(sys, a, b)) + xv(i)
      end do
      ! C = a0 M + a1 K + dashpots
      sys%a0 = ca0
      sys%a1 = ca1
      sys%rayleigh_c = size(di) == 0
      sys%cmat = ca1*sys%kmat
      do i = 1, n
         a = idx(sys, i, i)
         sys%cmat(a) = sys%cmat(a) + ca0*sys%mass(i)
      end do
      do i = 1, size(di)
         call add_link(sys, sys%cmat, di(i), dj(i), dc(i))
      end do
   end subroutine assemble

   !> A copy of a system set up by spd_setup (another step size starts from it): memory that
   !> cannot be had is an error, not a stop of the runtime in an assignment.
   subroutine spd_copy(src, dst, error)
      type(spd_system), intent(in) :: src                 !! a system set up
      type(spd_system), intent(out) :: dst                !! its copy
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      integer :: stat

      allocate (dst%perm(size(src%perm)), dst%inv(size(src%inv)), dst%dlo(size(src%dlo)), &
                dst%dhi(size(src%dhi)), dst%dorder(size(src%dorder)), dst%dptr(size(src%dptr)), &
                dst%dcol(size(src%dcol)), dst%dval(size(src%dval)), dst%mass(size(src%mass)), &
                dst%kmat(size(src%kmat)), dst%cmat(size(src%cmat)), dst%fac(size(src%fac)), &
                dst%kd(size(src%kd)), dst%errcol(size(src%errcol)), dst%w1(size(src%w1)), &
                dst%w2(size(src%w2)), dst%xv(size(src%xv)), dst%rdiag(size(src%rdiag)), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for another copy of the effective stiffness of "// &
                          trim(fmt_int(src%n))//" DOFs of half-bandwidth "//trim(fmt_int(src%kb))// &
                          " (one per step size)", stat_no_memory)
         return
      end if
      dst = src   ! every array already has its shape: nothing is allocated here
   end subroutine spd_copy

   !> A list of entries (i, j, value) that spd_setup takes whole or not at all: its copy, or
   !> an empty one when absent (names: the three arguments' names, for the message).
   subroutine optional_entries(names, ei, ej, ev, error, pi, pj, pv)
      character(len=*), intent(in) :: names
      integer, allocatable, intent(out) :: ei(:), ej(:)
      real(dp), allocatable, intent(out) :: ev(:)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: pi(:), pj(:)
      real(dp), intent(in), optional :: pv(:)

      if (present(pi) .and. present(pj) .and. present(pv)) then
         ei = pi
         ej = pj
         ev = pv
      else if (present(pi) .or. present(pj) .or. present(pv)) then
         call fatal_error(error, "spd_setup: "//names//" go together")
      else
         allocate (ei(0), ej(0), ev(0))
      end if
   end subroutine optional_entries

   !> Check the entries of K_x: rows and columns in 1..n with row <= column, finite values.
   subroutine check_entries(xi, xj, xv, n, error)
      integer, intent(in) :: xi(:), xj(:), n
      real(dp), intent(in) :: xv(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: e

      if (size(xj) /= size(xi) .or. size(xv) /= size(xi)) then
         call fatal_error(error, "spd_setup: kx_i, kx_j and kx_v differ in size")
         return
      end if
      do e = 1, size(xi)
         if (xi(e) < 1 .or. xj(e) > n .or. xi(e) > xj(e)) then
            call fatal_error(error, "spd_setup: entry "//trim(fmt_int(e))//" of K_x is at ("// &
                             trim(fmt_int(xi(e)))//", "//trim(fmt_int(xj(e)))//"), not 1 <= i <= j <= "// &
                             trim(fmt_int(n)))
            return
         end if
         if (.not. ieee_is_finite(xv(e))) then
            call fatal_error(error, "spd_setup: entry "//trim(fmt_int(e))//" of K_x is "//trim(fmt_real(xv(e))))
            return
         end if
      end do
   end subroutine check_entries

   !> Check the devices' terms: each device has one or more, on distinct DOFs in 1..n, with
   !> finite coefficients other than 0.
   subroutine check_devices(ptr, dof, coef, n, error)
      integer, intent(in) :: ptr(:), dof(:)
      real(dp), intent(in) :: coef(:)
      integer, intent(in) :: n
      type(error_type), allocatable, intent(out) :: error
      integer :: d, k, l

      if (size(ptr) < 1) then
         call fatal_error(error, "spd_setup: dev_ptr must have the number of devices + 1 entries")
         return
      end if
      if (ptr(1) /= 1 .or. ptr(size(ptr)) - 1 > min(size(dof), size(coef))) then
         call fatal_error(error, "spd_setup: dev_ptr does not index dev_dof and dev_coef (from 1 to "// &
                          trim(fmt_int(ptr(size(ptr)) - 1))//" terms)")
         return
      end if
      do d = 1, size(ptr) - 1
         if (ptr(d + 1) <= ptr(d)) then
            call fatal_error(error, "spd_setup: device "//trim(fmt_int(d))//" has no term")
            return
         end if
         do k = ptr(d), ptr(d + 1) - 1
            if (dof(k) < 1 .or. dof(k) > n) then
               call fatal_error(error, "spd_setup: device "//trim(fmt_int(d))//" has a term at DOF "// &
                                trim(fmt_int(dof(k)))//", outside 1.."//trim(fmt_int(n)))
               return
            end if
            if (.not. (coef(k) /= 0.0_dp .and. ieee_is_finite(coef(k)))) then
               call fatal_error(error, "spd_setup: device "//trim(fmt_int(d))//" has the coefficient "// &
                                trim(fmt_real(coef(k)))//" at DOF "//trim(fmt_int(dof(k)))// &
                                ", which must be finite and not 0")
               return
            end if
            do l = ptr(d), k - 1
               if (dof(l) == dof(k)) then
                  call fatal_error(error, "spd_setup: device "//trim(fmt_int(d))//" has two terms at DOF "// &
                                   trim(fmt_int(dof(k))))
                  return
               end if
            end do
         end do
      end do
   end subroutine check_devices

   !> The devices' terms in the new order, their first and last columns, and the signs that
   !> make each device's term in its first column positive (b b' does not change).
   subroutine order_devices(sys, ptr, dof, coef)
      type(spd_system), intent(inout) :: sys
      integer, intent(in) :: ptr(:), dof(:)
      real(dp), intent(in) :: coef(:)
      integer :: d, k, lo, hi, c
      real(dp) :: sgn

      sys%dptr = ptr(1:sys%nd + 1)
      do d = 1, sys%nd
         lo = sys%n + 1
         hi = 0
         sgn = 1.0_dp
         do k = ptr(d), ptr(d + 1) - 1
            c = sys%inv(dof(k))
            sys%dcol(k) = c
            if (c < lo) then
               lo = c
               sgn = sign(1.0_dp, coef(k))
            end if
            hi = max(hi, c)
         end do
         do k = ptr(d), ptr(d + 1) - 1
            sys%dval(k) = sgn*coef(k)
         end do
         sys%dlo(d) = lo
         sys%dhi(d) = hi
         if (hi == lo) sys%dhi(d) = 0
      end do
   end subroutine order_devices

   !> Check the nodes and coefficients of a list of two-node elements.
   subroutine check_links(what, ni, nj, coef, n, error)
      character(len=*), intent(in) :: what
      integer, intent(in) :: ni(:), nj(:)
      real(dp), intent(in) :: coef(:)
      integer, intent(in) :: n
      type(error_type), allocatable, intent(out) :: error
      integer :: e

      do e = 1, size(ni)
         if (ni(e) < 0 .or. ni(e) > n .or. nj(e) < 0 .or. nj(e) > n) then
            call fatal_error(error, "spd_setup: "//what//" "//trim(fmt_int(e))//" joins nodes "// &
                             trim(fmt_int(ni(e)))//" and "//trim(fmt_int(nj(e)))//", outside 0.."// &
                             trim(fmt_int(n)))
            return
         end if
         if (ni(e) == nj(e)) then
            call fatal_error(error, "spd_setup: "//what//" "//trim(fmt_int(e))//" joins node "// &
                             trim(fmt_int(ni(e)))//" to itself")
            return
         end if
         if (.not. (coef(e) >= 0.0_dp .and. ieee_is_finite(coef(e)))) then
            call fatal_error(error, "spd_setup: "//what//" "//trim(fmt_int(e))//" has the coefficient "// &
                             trim(fmt_real(coef(e)))//", which must be finite and >= 0")
            return
         end if
      end do
   end subroutine check_links

   !> Add a two-node element of coefficient k between old nodes i and j (0 = table).
   subroutine add_link(sys, mat, i, j, k)
      type(spd_system), intent(in) :: sys
      real(dp), intent(inout) :: mat(:)
      integer, intent(in) :: i, j
      real(dp), intent(in) :: k
      integer :: a, b, t

      a = 0
      b = 0
      if (i > 0) a = sys%inv(i)
      if (j > 0) b = sys%inv(j)
      if (a > 0) mat(idx(sys, a, a)) = mat(idx(sys, a, a)) + k
      if (b > 0) mat(idx(sys, b, b)) = mat(idx(sys, b, b)) + k
      if (a > 0 .and. b > 0) then
         if (a > b) then
            t = a; a = b; b = t
         end if
         mat(idx(sys, a, b)) = mat(idx(sys, a, b)) - k
      end if
   end subroutine add_link

   !> Devices by decreasing last column (insertion into buckets by column).
   subroutine sort_devices(sys)
      type(spd_system), intent(inout) :: sys
      integer, allocatable :: cnt(:)
      integer :: d, c, pos

      allocate (cnt(0:sys%n + 1))
      cnt = 0
      do d = 1, sys%nd
         c = max(sys%dlo(d), sys%dhi(d))
         cnt(c) = cnt(c) + 1
      end do
      ! start of each column's bucket, columns n..1
      pos = 1
      do c = sys%n, 1, -1
         d = cnt(c)
         cnt(c) = pos
         pos = pos + d
      end do
      do d = 1, sys%nd
         c = max(sys%dlo(d), sys%dhi(d))
         sys%dorder(cnt(c)) = d
         cnt(c) = cnt(c) + 1
      end do
   end subroutine sort_devices

   !> Position of U(i, j), i <= j, in the storage.
   pure integer function idx(sys, i, j)
      type(spd_system), intent(in) :: sys
      integer, intent(in) :: i, j

      idx = i + j*sys%sj + sys%off
   end function idx

   !> Factor K^ = K + c1 C + c0 M + sum_d kd_d b_d b_d' from scratch.
   subroutine spd_factor(sys, c0, c1, kd, error)
      type(spd_system), intent(inout) :: sys     !! the system (set up)
      real(dp), intent(in) :: c0                 !! coefficient of M, >= 0
      real(dp), intent(in) :: c1                 !! coefficient of C, >= 0
      real(dp), intent(in) :: kd(:)              !! device stiffness, one per device, >= 0
      type(error_type), allocatable, intent(out) :: error !! bad input, K^ not positive definite
      integer :: d

      if (.not. allocated(sys%fac)) then
         call fatal_error(error, "spd_factor: the system is not set up (call spd_setup)")
         return
      end if
      if (.not. (c0 >= 0.0_dp .and. c1 >= 0.0_dp .and. ieee_is_finite(c0) .and. ieee_is_finite(c1))) then
         call fatal_error(error, "spd_factor: c0 = "//trim(fmt_real(c0))//" and c1 = "//trim(fmt_real(c1))// &
                          " must be finite and >= 0")
         return
      end if
      if (size(kd) /= sys%nd) then
         call fatal_error(error, "spd_factor: "//trim(fmt_int(size(kd)))//" device stiffnesses given for "// &
                          trim(fmt_int(sys%nd))//" devices")
         return
      end if
      do d = 1, sys%nd
         call check_kd("spd_factor", d, kd(d), error)
         if (allocated(error)) return
      end do
      sys%c0 = c0
      sys%c1 = c1
      sys%kd(:) = kd
      sys%span = huge(1.0_dp)
      call full_factor(sys, error)
   end subroutine spd_factor

   subroutine check_kd(where, d, kd, error)
      character(len=*), intent(in) :: where
      integer, intent(in) :: d
      real(dp), intent(in) :: kd
      type(error_type), allocatable, intent(out) :: error

      if (.not. (kd >= 0.0_dp .and. ieee_is_finite(kd))) then
         call fatal_error(error, where//": device "//trim(fmt_int(d))//" stiffness "//trim(fmt_real(kd))// &
                          " must be finite and >= 0")
      end if
   end subroutine check_kd

   !> Factor from column 1; resets the error estimate.
   subroutine full_factor(sys, error)
      type(spd_system), intent(inout) :: sys
      type(error_type), allocatable, intent(out) :: error

      sys%stats%factorizations = sys%stats%factorizations + 1
      sys%errcol = 0.0_dp
      call refactor_from(sys, 1, error)
   end subroutine full_factor

   !> Refactor after an abandoned modification (a lost pivot, or the error budget reached):
   !> from its first column p, or from the first column whose estimated error has used a
   !> quarter of the budget if that comes earlier, so that every column has room for updates
   !> again. Columns before that are kept: a refresh costs O((n - q) band^2), not a factorization
   !> from scratch (unless q = 1).
   subroutine refresh(sys, p, error)
      type(spd_system), intent(inout) :: sys
      integer, intent(in) :: p
      type(error_type), allocatable, intent(out) :: error
      integer :: q, j

      q = p
      do j = 1, p - 1
         if (sys%errcol(j) > 0.25_dp*sys%budget) then
            q = j
            exit
         end if
      end do
      if (q <= 1) then
         call full_factor(sys, error)
      else
         call refactor_from(sys, q, error)
      end if
   end subroutine refresh

   !> Recompute the factor from column p on (columns before p are kept): assemble columns
   !> p..n of K^, subtract the rows of U above p (U22' U22 = A22 - U12' U12), factor.
   subroutine refactor_from(sys, p, error)
      type(spd_system), intent(inout) :: sys
      integer, intent(in) :: p
      type(error_type), allocatable, intent(out) :: error
      integer :: i, j, l, k, m, d, n, kb, info, r, q
      real(dp) :: s, e

      n = sys%n
      kb = sys%kb
      sys%factored = .false.
      associate (fac => sys%fac, kmat => sys%kmat, cmat => sys%cmat)
         do j = p, n
            do i = max(p, j - kb), j
               k = idx(sys, i, j)
               fac(k) = kmat(k) + sys%c1*cmat(k)
            end do
            k = idx(sys, j, j)
            fac(k) = fac(k) + sys%c0*sys%mass(j)
         end do
         ! kd b b', in the columns from p on
         do m = 1, sys%nd
            d = sys%dorder(m)
            if (max(sys%dlo(d), sys%dhi(d)) < p) exit
            if (sys%kd(d) == 0.0_dp) cycle
            do r = sys%dptr(d), sys%dptr(d + 1) - 1
               i = sys%dcol(r)
               if (i < p) cycle
               do q = sys%dptr(d), sys%dptr(d + 1) - 1
                  j = sys%dcol(q)
                  if (j < i) cycle
                  k = idx(sys, i, j)
                  fac(k) = fac(k) + sys%kd(d)*sys%dval(r)*sys%dval(q)
               end do
            end do
         end do
         do j = p, n
            sys%w2(j) = fac(idx(sys, j, j))
         end do
         if (p > 1) then
            if (sys%dense) then
               call dsyrk('U', 'T', n - p + 1, p - 1, -1.0_dp, fac(idx(sys, 1, p)), n, 1.0_dp, &
                          fac(idx(sys, p, p)), n)
            else
               do j = p, min(n, p + kb - 1)
                  do i = p, j
                     s = 0.0_dp
                     do l = max(1, j - kb), p - 1
                        s = s + fac(idx(sys, l, i))*fac(idx(sys, l, j))
                     end do
                     k = idx(sys, i, j)
                     fac(k) = fac(k) - s
                  end do
               end do
            end if
         end if
         ! the unblocked kernels where the blocked drivers would choose them anyway (dpbtrf
         ! for a band <= 64) or lose to them (dpotrf below 64): no ilaenv query per call
         if (sys%dense .and. n - p + 1 <= unblocked_max) then
            call dpotf2('U', n - p + 1, fac(idx(sys, p, p)), n, info)
         else if (sys%dense) then
            call dpotrf('U', n - p + 1, fac(idx(sys, p, p)), n, info)
         else if (kb <= narrow_band) then
            call band_potf2(n - p + 1, kb, fac(idx(sys, p, p) - kb), sys%ld, info)
         else if (kb <= unblocked_max) then
            call dpbtf2('U', n - p + 1, kb, fac(idx(sys, p, p) - kb), sys%ld, info)
         else
            call dpbtrf('U', n - p + 1, kb, fac(idx(sys, p, p) - kb), sys%ld, info)
         end if
      end associate
      if (info /= 0) then
         k = info + p - 1
         call fatal_error(error, "the effective stiffness is not positive definite (pivot of DOF "// &
                          trim(fmt_int(sys%perm(min(max(k, 1), n))))//")")
         return
      end if
      ! a pivot at the level of the rounding error of the factorization: numerically singular
      do j = p, n
         s = sys%fac(idx(sys, j, j))
         if (s*s <= singular_tol*(min(kb, j - 1) + 1)*sys%w2(j)) then
            call fatal_error(error, "the effective stiffness is numerically singular: the pivot of DOF "// &
                             trim(fmt_int(sys%perm(j)))//" is "//trim(fmt_real(s*s))//" for a diagonal of "// &
                             trim(fmt_real(sys%w2(j)))//" (not positive definite to working precision)")
            return
         end if
      end do
      ! the recomputed columns inherit the error of the rows of U above them
      e = 0.0_dp
      if (p > 1) e = maxval(sys%errcol(max(1, p - kb):p - 1))
      sys%errcol(p:n) = e
      do j = p, n
         sys%rdiag(j) = 1.0_dp/sys%fac(idx(sys, j, j))
      end do
      sys%factored = .true.
   end subroutine refactor_from

   !> Change the stiffness of one device to kd and update the factor accordingly.
   subroutine spd_update_device(sys, d, kd, error)
      type(spd_system), intent(inout) :: sys     !! the system (factored)
      integer, intent(in) :: d                   !! device, 1..number of devices
      real(dp), intent(in) :: kd                 !! its new stiffness, >= 0
      type(error_type), allocatable, intent(out) :: error !! bad input, not factored, K^ not SPD
      integer :: p
      logical :: ok

      if (.not. sys%factored) then
         call fatal_error(error, "spd_update_device: the system is not factored (call spd_factor)")
         return
      end if
      if (d < 1 .or. d > sys%nd) then
         call fatal_error(error, "spd_update_device: device "//trim(fmt_int(d))//" is not in 1.."// &
                          trim(fmt_int(sys%nd)))
         return
      end if
      call check_kd("spd_update_device", d, kd, error)
      if (allocated(error)) return
      if (kd == sys%kd(d)) return
      p = sys%dlo(d)
      if (prefer_refactor(sys, cost_refactor(sys, p), cost_update(sys, p))) then
         sys%kd(d) = kd
         sys%stats%partial = sys%stats%partial + 1
         call refactor_from(sys, p, error)
      else
         call modify(sys, d, kd, ok)
         if (.not. ok) call refresh(sys, p, error)
      end if
   end subroutine spd_update_device

   !> Change the stiffness of every device to kd(:) and update the factor: rank-one updates
   !> (the stiffnesses that grew first, then downdates), or a refactorization from the first
   !> changed column when that costs fewer operations.
   subroutine spd_update_devices(sys, kd, error)
      type(spd_system), intent(inout) :: sys     !! the system (factored)
      real(dp), intent(in) :: kd(:)              !! new device stiffness, one per device, >= 0
      type(error_type), allocatable, intent(out) :: error !! bad input, not factored, K^ not SPD
      integer :: d, p, pass
      real(dp) :: cost
      logical :: ok

      if (.not. sys%factored) then
         call fatal_error(error, "spd_update_devices: the system is not factored (call spd_factor)")
         return
      end if
      if (size(kd) /= sys%nd) then
         call fatal_error(error, "spd_update_devices: "//trim(fmt_int(size(kd)))// &
                          " device stiffnesses given for "//trim(fmt_int(sys%nd))//" devices")
         return
      end if
      p = sys%n + 1
      cost = 0.0_dp
      do d = 1, sys%nd
         call check_kd("spd_update_devices", d, kd(d), error)
         if (allocated(error)) return
         if (kd(d) == sys%kd(d)) cycle
         p = min(p, sys%dlo(d))
         cost = cost + cost_update(sys, sys%dlo(d))
      end do
      if (p > sys%n) return
      if (prefer_refactor(sys, cost_refactor(sys, p), cost)) then
         sys%kd(:) = kd
         sys%stats%partial = sys%stats%partial + 1
         call refactor_from(sys, p, error)
         return
      end if
      do pass = 1, 2
         do d = 1, sys%nd
            if (kd(d) == sys%kd(d)) cycle
            if ((pass == 1) .neqv. (kd(d) > sys%kd(d))) cycle
            call modify(sys, d, kd(d), ok)
            if (.not. ok) then
               sys%kd(:) = kd
               call refresh(sys, p, error)
               return
            end if
         end do
      end do
   end subroutine spd_update_devices

   !> Rank-one update or downdate of the factor for device d's stiffness becoming kd. A
   !> downdate that loses its pivot, or any modification that would exceed the error budget,
   !> is abandoned (ok false, counted): the caller refactors.
   subroutine modify(sys, d, kd, ok)
      type(spd_system), intent(inout) :: sys
      integer, intent(in) :: d
      real(dp), intent(in) :: kd
      logical, intent(out) :: ok
      real(dp) :: delta
      integer :: status

      delta = kd - sys%kd(d)
      sys%kd(d) = kd
      call rank_one(sys, d, delta, status)
      ok = status == 0
      select case (status)
      case (0)
         if (delta > 0.0_dp) then
            sys%stats%updates = sys%stats%updates + 1
         else
            sys%stats%downdates = sys%stats%downdates + 1
         end if
      case (1)
         sys%stats%fallbacks = sys%stats%fallbacks + 1
      case default
         sys%stats%refreshes = sys%stats%refreshes + 1
      end select
   end subroutine modify

   !> U' U + delta v v' -> U' U, v = b_d (columns dlo to dhi, positive in dlo): hyperbolic
   !> (delta < 0) or circular (delta > 0) rotations in the mixed form, column a to n,
   !> touching the band only. The rotations stop early once the rest of the update vector
   !> is negligible: when every remaining entry x_j satisfies |x_j| <= tau U_jj, the
   !> neglected x x' is at most tau^2 = eps/4 relative to the diagonal (below rounding). In a
   !> diagonally dominant K^ (inertia c0 M against springs, as at Newmark's small steps) the
   !> change of the factor decays geometrically along the band, so an update costs a few
   !> decay lengths, not n. status: 0 done; 1 abandoned, a pivot collapsed (the downdate
   !> alone loses more than the budget); 2 abandoned, the accumulated error estimate would
   !> exceed the budget. An abandoned modification leaves the factor partly modified and
   !> marked not factored.
   subroutine rank_one(sys, d, delta, status)
      type(spd_system), intent(inout) :: sys
      integer, intent(in) :: d
      real(dp), intent(in) :: delta
      integer, intent(out) :: status
      real(dp) :: x, xk, ukk, s, ratio, c, ci, e, u
      integer :: k, j, jmax, last, kk, ij, n, kb, sj, a
      logical :: up

      status = 0
      n = sys%n
      kb = sys%kb
      sj = sys%sj
      up = delta > 0.0_dp
      x = sqrt(abs(delta))
      associate (fac => sys%fac, xv => sys%xv, errcol => sys%errcol)
         do k = sys%dptr(d), sys%dptr(d + 1) - 1
            xv(sys%dcol(k)) = x*sys%dval(k)
         end do
         a = sys%dlo(d)
         last = max(a, sys%dhi(d))
         k = a
         do while (k <= last)
            xk = xv(k)
            if (xk == 0.0_dp) then
               k = k + 1
               cycle
            end if
            kk = idx(sys, k, k)
            ukk = fac(kk)
            if (abs(xk) <= truncate_tol*ukk) then
               if (negligible(sys, k + 1, min(last, k + kb))) then
                  do j = k, min(last, k + kb)
                     errcol(j) = errcol(j) + truncate_tol**2
                     xv(j) = 0.0_dp
                  end do
                  exit
               end if
            end if
            xv(k) = 0.0_dp
            s = xk/ukk
            if (up) then
               ratio = 1.0_dp + s*s
            else
               ratio = (1.0_dp - s)*(1.0_dp + s)
            end if
            e = (errcol(k) + unit_error)/ratio
            if (.not. (ratio > 0.0_dp .and. e <= sys%budget)) then
               status = 2
               if (.not. (ratio > 0.0_dp .and. unit_error <= sys%budget*ratio)) status = 1
               xv(k:min(n, k + kb)) = 0.0_dp
               sys%factored = .false.
               return
            end if
            errcol(k) = e
            c = sqrt(ratio)
            ci = 1.0_dp/c
            fac(kk) = ukk*c
            sys%rdiag(k) = 1.0_dp/fac(kk)
            jmax = min(n, k + kb)
            ij = kk
            if (up) then
               do j = k + 1, jmax
                  ij = ij + sj
                  u = (fac(ij) + s*xv(j))*ci
                  fac(ij) = u
                  xv(j) = c*xv(j) - s*u
               end do
            else
               do j = k + 1, jmax
                  ij = ij + sj
                  u = (fac(ij) - s*xv(j))*ci
                  fac(ij) = u
                  xv(j) = c*xv(j) - s*u
               end do
            end if
            last = max(last, jmax)
            k = k + 1
         end do
      end associate
      ! columns touched, and their running average (the cost model's length of an update)
      k = min(k, n + 1) - a
      sys%stats%update_columns = sys%stats%update_columns + k
      sys%span = 0.875_dp*sys%span + 0.125_dp*real(k, dp)
   end subroutine rank_one

   !> Whether every entry of the update vector in columns j1..j2 is negligible.
   pure logical function negligible(sys, j1, j2)
      type(spd_system), intent(in) :: sys
      integer, intent(in) :: j1, j2
      integer :: j

      negligible = .false.
      do j = j1, j2
         if (abs(sys%xv(j)) > truncate_tol*sys%fac(idx(sys, j, j))) return
      end do
      negligible = .true.
   end function negligible

   !> Whether to refactor rather than modify, by the method or the operation counts.
   pure logical function prefer_refactor(sys, refactor, modify)
      type(spd_system), intent(in) :: sys
      real(dp), intent(in) :: refactor, modify

      select case (sys%method)
      case (spd_rank_one)
         prefer_refactor = .false.
      case (spd_refactor)
         prefer_refactor = .true.
      case default
         prefer_refactor = refactor < modify
      end select
   end function prefer_refactor

   !> Sums over the columns k = p..n of min(kb, n - k) and of its square.
   pure subroutine band_sums(n, kb, p, s1, s2)
      integer, intent(in) :: n, kb, p
      real(dp), intent(out) :: s1, s2
      real(dp) :: m, b

      m = real(n - p, dp)
      b = real(kb, dp)
      if (m <= b) then
         s1 = m*(m + 1.0_dp)/2.0_dp
         s2 = m*(m + 1.0_dp)*(2.0_dp*m + 1.0_dp)/6.0_dp
      else
         s1 = b*(b + 1.0_dp)/2.0_dp + (m - b)*b
         s2 = b*(b + 1.0_dp)*(2.0_dp*b + 1.0_dp)/6.0_dp + (m - b)*b*b
      end if
   end subroutine band_sums

   !> Operations of one rank-one modification from column p: n - p + 1 columns, or as many
   !> as the recent updates touched before their change decayed below rounding.
   pure real(dp) function cost_update(sys, p)
      type(spd_system), intent(in) :: sys
      integer, intent(in) :: p
      real(dp) :: cols

      cols = min(real(sys%n - p + 1, dp), sys%span)
      cost_update = cols*(w_update + real(min(sys%kb, sys%n - p), dp))
   end function cost_update

   !> Operations of a refactorization from column p (the rows above p included).
   pure real(dp) function cost_refactor(sys, p)
      type(spd_system), intent(in) :: sys
      integer, intent(in) :: p
      real(dp) :: s1, s2, r, c

      call band_sums(sys%n, sys%kb, p, s1, s2)
      r = real(min(sys%kb, p - 1), dp)
      c = real(min(sys%kb, sys%n - p + 1), dp)
      cost_refactor = w_factor*real(sys%n - p + 1, dp) + 2.0_dp*s1 + s2 + r*c*c
   end function cost_refactor

   !> Solve K^ x = b with the current factor; b is overwritten by x (original DOF order).
   subroutine spd_solve(sys, b, error)
      type(spd_system), intent(inout) :: sys     !! the system (factored)
      real(dp), intent(inout), contiguous :: b(:) !! right-hand side on entry, solution on exit
      type(error_type), allocatable, intent(out) :: error !! not factored, wrong size
      integer :: i, info

      if (.not. sys%factored) then
         call fatal_error(error, "spd_solve: the system is not factored (call spd_factor)")
         return
      end if
      if (size(b) /= sys%n) then
         call fatal_error(error, "spd_solve: right-hand side of size "//trim(fmt_int(size(b)))// &
                          " for "//trim(fmt_int(sys%n))//" DOFs")
         return
      end if
      if (sys%dense) then
         ! U' U x = b: two triangular solves (dpotrs's work without its level-3 call overhead);
         ! for a few DOFs the loops of the reference dtrsv, without the call (a step of a
         ! two-mass model costs tens of nanoseconds: the calls were a third of it)
         if (sys%n <= spd_dense_max_n) then
            call small_solve(sys%n, sys%fac, sys%rdiag, b)
         else
            call dtrsv('U', 'T', 'N', sys%n, sys%fac, sys%ld, b, 1)
            call dtrsv('U', 'N', 'N', sys%n, sys%fac, sys%ld, b, 1)
         end if
      else
         do i = 1, sys%n
            sys%w1(i) = b(sys%perm(i))
         end do
         if (sys%kb <= narrow_band) then
            call band_solve(sys%n, sys%kb, sys%fac, sys%rdiag, sys%w1)
         else
            call dpbtrs('U', sys%n, sys%kb, 1, sys%fac, sys%ld, sys%w1, sys%n, info)
         end if
         do i = 1, sys%n
            b(sys%perm(i)) = sys%w1(i)
         end do
      end if
   end subroutine spd_solve

   !> y = alpha K x + beta y (original DOF order; y is not read when beta = 0).
   subroutine spd_k_matvec(sys, x, y, alpha, beta)
      type(spd_system), intent(inout) :: sys     !! the system (set up)
      real(dp), intent(in), contiguous :: x(:)   !! vector, size n
      real(dp), intent(inout), contiguous :: y(:) !! result, size n
      real(dp), intent(in) :: alpha              !! factor of K x
      real(dp), intent(in) :: beta               !! factor of the incoming y

      call band_matvec(sys, sys%kmat, x, y, alpha, beta)
   end subroutine spd_k_matvec

   !> y = alpha C x + beta y (original DOF order; y is not read when beta = 0).
   subroutine spd_c_matvec(sys, x, y, alpha, beta)
      type(spd_system), intent(inout) :: sys     !! the system (set up)
      real(dp), intent(in), contiguous :: x(:)   !! vector, size n
      real(dp), intent(inout), contiguous :: y(:) !! result, size n
      real(dp), intent(in) :: alpha              !! factor of C x
      real(dp), intent(in) :: beta               !! factor of the incoming y

      call band_matvec(sys, sys%cmat, x, y, alpha, beta)
   end subroutine spd_c_matvec

   !> y = y + alpha (K x + C z) (original DOF order). When C = a0 M + a1 K (no dashpots) one
   !> product, K (x + a1 z) + a0 M z, instead of two: what a Newmark step needs.
   subroutine spd_kc_matvec(sys, x, z, y, alpha)
      type(spd_system), intent(inout) :: sys     !! the system (set up)
      real(dp), intent(in), contiguous :: x(:)   !! vector multiplied by K, size n
      real(dp), intent(in), contiguous :: z(:)   !! vector multiplied by C, size n
      real(dp), intent(inout), contiguous :: y(:) !! result, size n (added to)
      real(dp), intent(in) :: alpha              !! factor of K x + C z
      integer :: i, p

      if (.not. sys%rayleigh_c) then
         call band_matvec(sys, sys%kmat, x, y, alpha, 1.0_dp)
         call band_matvec(sys, sys%cmat, z, y, alpha, 1.0_dp)
         return
      end if
      if (sys%dense .and. sys%n <= spd_dense_max_n) then
         ! (before the associate below, whose five names cost more than this product)
         call small_kc_matvec(sys%n, sys%kmat, sys%a0, sys%a1, sys%mass, x, z, y, alpha)
         return
      end if
      associate (n => sys%n, w1 => sys%w1, w2 => sys%w2, perm => sys%perm, mass => sys%mass)
         if (sys%dense) then
            do i = 1, n
               w1(i) = x(i) + sys%a1*z(i)
            end do
            call dsymv('U', n, 1.0_dp, sys%kmat, sys%ld, w1, 1, 0.0_dp, w2, 1)
            do i = 1, n
               y(i) = y(i) + alpha*(w2(i) + sys%a0*mass(i)*z(i))
            end do
         else
            do i = 1, n
               p = perm(i)
               w1(i) = x(p) + sys%a1*z(p)
            end do
            if (sys%kb <= narrow_band) then
               call band_symv(n, sys%kb, sys%kmat, w1, w2)
            else
               call dsbmv('U', n, sys%kb, 1.0_dp, sys%kmat, sys%ld, w1, 1, 0.0_dp, w2, 1)
            end if
            do i = 1, n
               p = perm(i)
               y(p) = y(p) + alpha*(w2(i) + sys%a0*mass(i)*z(p))
            end do
         end if
      end associate
   end subroutine spd_kc_matvec

   subroutine band_matvec(sys, mat, x, y, alpha, beta)
      type(spd_system), intent(inout) :: sys
      real(dp), intent(in), contiguous :: mat(:)
      real(dp), intent(in), contiguous :: x(:)
      real(dp), intent(inout), contiguous :: y(:)
      real(dp), intent(in) :: alpha, beta
      integer :: i

      if (sys%dense) then
         if (sys%n <= spd_dense_max_n) then
            call small_symv(sys%n, mat, x, y, alpha, beta)
            return
         end if
         if (beta == 0.0_dp) y = 0.0_dp
         call dsymv('U', sys%n, alpha, mat, sys%ld, x, 1, beta, y, 1)
         return
      end if
      do i = 1, sys%n
         sys%w1(i) = x(sys%perm(i))
      end do
      if (sys%kb <= narrow_band) then
         call band_symv(sys%n, sys%kb, mat, sys%w1, sys%w2)
      else
         call dsbmv('U', sys%n, sys%kb, 1.0_dp, mat, sys%ld, sys%w1, 1, 0.0_dp, sys%w2, 1)
      end if
      if (beta == 0.0_dp) then
         do i = 1, sys%n
            y(sys%perm(i)) = alpha*sys%w2(i)
         end do
      else
         do i = 1, sys%n
            y(sys%perm(i)) = alpha*sys%w2(i) + beta*y(sys%perm(i))
         end do
      end if
   end subroutine band_matvec

   !> U' U x = b for a small dense upper factor (n x n, column-major), b overwritten: the
   !> loops of the reference BLAS dtrsv ('U', 'T') then dtrsv ('U', 'N'), with the divisions by
   !> the pivots made multiplications by their reciprocals (kept with the factor): the solve
   !> of a two-mass model waited on four divisions.
   pure subroutine small_solve(n, u, rdiag, b)
      integer, intent(in) :: n
      real(dp), intent(in) :: u(n, n), rdiag(n)
      real(dp), intent(inout) :: b(n)
      real(dp) :: temp
      integer :: i, j

      if (n == 2) then  ! the loops below for two DOFs, written out (the paper's two masses)
         b(1) = b(1)*rdiag(1)
         b(2) = (b(2) - u(1, 2)*b(1))*rdiag(2)
         b(2) = b(2)*rdiag(2)
         b(1) = (b(1) - b(2)*u(1, 2))*rdiag(1)
         return
      end if
      do j = 1, n
         temp = b(j)
         !GCC$ novector
         do i = 1, j - 1
            temp = temp - u(i, j)*b(i)
         end do
         b(j) = temp*rdiag(j)
      end do
      do j = n, 1, -1
         b(j) = b(j)*rdiag(j)
         temp = b(j)
         !GCC$ novector
         do i = j - 1, 1, -1
            b(i) = b(i) - temp*u(i, j)
         end do
      end do
   end subroutine small_solve

   !> U' U x = b for an upper band factor of half-bandwidth kb (LAPACK's band layout, U(i, j)
   !> at i + j kb), b overwritten: dpbtrs's two dtbsv, in their order, with the divisions by
   !> the pivots made multiplications by their reciprocals and the band loops written for a
   !> narrow band (a shear building's is 1: the reference dtbsv spent most of a step's solve in
   !> its index arithmetic).
   pure subroutine band_solve(n, kb, u, rdiag, b)
      integer, intent(in) :: n, kb
      real(dp), intent(in) :: u(*), rdiag(n)
      real(dp), intent(inout) :: b(n)
      real(dp) :: temp
      integer :: i, j

      if (kb == 1) then
         b(1) = b(1)*rdiag(1)
         do j = 2, n
            b(j) = (b(j) - u(2*j - 1)*b(j - 1))*rdiag(j)
         end do
         do j = n, 2, -1
            b(j) = b(j)*rdiag(j)
            b(j - 1) = b(j - 1) - b(j)*u(2*j - 1)
         end do
         b(1) = b(1)*rdiag(1)
         return
      end if
      do j = 1, n
         temp = b(j)
         do i = max(1, j - kb), j - 1
            temp = temp - u(i + j*kb)*b(i)
         end do
         b(j) = temp*rdiag(j)
      end do
      do j = n, 1, -1
         b(j) = b(j)*rdiag(j)
         temp = b(j)
         do i = j - 1, max(1, j - kb), -1
            b(i) = b(i) - temp*u(i + j*kb)
         end do
      end do
   end subroutine band_solve

   !> The band Cholesky factor U' U of a narrow band in LAPACK's upper band storage (what
   !> dpbtf2('U', n, kd, ab, ldab, info) computes): the reference dpbtf2's loops with those of
   !> the dscal and dsyr it calls, in their order, so the same bits as LAPACK on the reference
   !> BLAS. For a band of 1 or 2 the two calls a column cost more than their arithmetic (259
   !> instructions a column for a chain). info: 0, or the column of the first pivot that is
   !> not positive (NaN included, which dpbtf2 would carry on with).
   pure subroutine band_potf2(n, kd, ab, ldab, info)
      integer, intent(in) :: n                   !! order
      integer, intent(in) :: kd                  !! superdiagonals, 0 <= kd < ldab
      integer, intent(in) :: ldab                !! leading dimension, A(i, j) in ab(kd + 1 + i - j, j)
      real(dp), intent(inout) :: ab(ldab, *)     !! in: A's upper band; out: U's
      integer, intent(out) :: info               !! 0, or the column of a pivot <= 0 or NaN
      integer :: j, kn, p, q
      real(dp) :: ajj, r, temp

      info = 0
      do j = 1, n
         ajj = ab(kd + 1, j)
         if (.not. (ajj > 0.0_dp)) then
            info = j
            return
         end if
         ajj = sqrt(ajj)
         ab(kd + 1, j) = ajj
         kn = min(kd, n - j)
         if (kn == 0) cycle
         ! dscal(kn, 1/ajj, ab(kd, j + 1), ldab - 1): row j of U right of the diagonal
         r = 1.0_dp/ajj
         do q = 1, kn
            ab(kd + 1 - q, j + q) = r*ab(kd + 1 - q, j + q)
         end do
         ! dsyr('U', kn, -1, that row, ldab - 1, ab(kd + 1, j + 1), ldab - 1): the trailing
         ! block within the band loses its outer product
         do q = 1, kn
            if (ab(kd + 1 - q, j + q) /= 0.0_dp) then
               temp = -ab(kd + 1 - q, j + q)
               do p = 1, q
                  ab(kd + 1 + p - q, j + q) = ab(kd + 1 + p - q, j + q) + ab(kd + 1 - p, j + p)*temp
               end do
            end if
         end do
      end do
   end subroutine band_potf2

   !> y = A x for a symmetric band A (upper band layout, A(i, j) at i + j kb): the loops of
   !> the reference dsbmv, written for a narrow band (a chain's is 1: a tridiagonal product).
   pure subroutine band_symv(n, kb, a, x, y)
      integer, intent(in) :: n, kb
      real(dp), intent(in) :: a(*), x(n)
      real(dp), intent(out) :: y(n)
      real(dp) :: temp1, temp2
      integer :: i, j

      if (kb == 1) then
         y(1) = a(2)*x(1)
         do j = 2, n
            y(j - 1) = y(j - 1) + x(j)*a(2*j - 1)
            y(j) = x(j)*a(2*j) + a(2*j - 1)*x(j - 1)
         end do
         return
      end if
      do j = 1, n
         temp1 = x(j)
         temp2 = 0.0_dp
         y(j) = 0.0_dp
         do i = max(1, j - kb), j - 1
            y(i) = y(i) + temp1*a(i + j*kb)
            temp2 = temp2 + a(i + j*kb)*x(i)
         end do
         y(j) = temp1*a(j + j*kb) + temp2
      end do
   end subroutine band_symv

   !> y = y + alpha (K (x + a1 z) + a0 M z) for a small dense K (upper triangle, n x n
   !> column-major, n <= spd_dense_max_n): the product in the order of small_symv (that of the
   !> reference dsymv), in one routine with explicit shapes and without work arrays, since at
   !> a step of a two-mass model the calls and array descriptors cost more than the product.
   !> Scalar loops: a vector load of what scalar stores just wrote stalls the store forwarding.
   pure subroutine small_kc_matvec(n, a, a0, a1, mass, x, z, y, alpha)
      integer, intent(in) :: n
      real(dp), intent(in) :: a(n, n), a0, a1, mass(n), x(n), z(n), alpha
      real(dp), intent(inout) :: y(n)
      real(dp) :: w(spd_dense_max_n), kw(spd_dense_max_n), temp1, temp2
      integer :: i, j

      if (n == 2) then  ! the loops below for two DOFs, written out, every operation kept
         w(1) = x(1) + a1*z(1)
         w(2) = x(2) + a1*z(2)
         kw(1) = 0.0_dp + w(1)*a(1, 1) + 0.0_dp
         kw(1) = kw(1) + w(2)*a(1, 2)
         kw(2) = 0.0_dp + w(2)*a(2, 2) + (0.0_dp + a(1, 2)*w(1))
         y(1) = y(1) + alpha*(kw(1) + a0*mass(1)*z(1))
         y(2) = y(2) + alpha*(kw(2) + a0*mass(2)*z(2))
         return
      end if
      !GCC$ novector
      do i = 1, n
         w(i) = x(i) + a1*z(i)
         kw(i) = 0.0_dp
      end do
      do j = 1, n
         temp1 = w(j)
         temp2 = 0.0_dp
         !GCC$ novector
         do i = 1, j - 1
            kw(i) = kw(i) + temp1*a(i, j)
            temp2 = temp2 + a(i, j)*w(i)
         end do
         kw(j) = kw(j) + temp1*a(j, j) + temp2
      end do
      !GCC$ novector
      do i = 1, n
         y(i) = y(i) + alpha*(kw(i) + a0*mass(i)*z(i))
      end do
   end subroutine small_kc_matvec

   !> y = alpha A x + beta y for a small symmetric A (upper triangle, n x n column-major): the
   !> operations of the reference BLAS dsymv ('U'), in its order (y not read when beta = 0).
   pure subroutine small_symv(n, a, x, y, alpha, beta)
      integer, intent(in) :: n
      real(dp), intent(in) :: a(n, n), x(n)
      real(dp), intent(inout) :: y(n)
      real(dp), intent(in) :: alpha, beta
      real(dp) :: temp1, temp2
      integer :: i, j

      if (beta == 0.0_dp) then
         !GCC$ novector
         do i = 1, n
            y(i) = 0.0_dp
         end do
      else if (beta /= 1.0_dp) then
         !GCC$ novector
         do i = 1, n
            y(i) = beta*y(i)
         end do
      end if
      if (alpha == 0.0_dp) return
      do j = 1, n
         temp1 = alpha*x(j)
         temp2 = 0.0_dp
         !GCC$ novector
         do i = 1, j - 1
            y(i) = y(i) + temp1*a(i, j)
            temp2 = temp2 + a(i, j)*x(i)
         end do
         y(j) = y(j) + temp1*a(j, j) + alpha*temp2
      end do
   end subroutine small_symv

   !> Number of DOFs.
   pure integer function spd_size(sys)
      type(spd_system), intent(in) :: sys !! the system

      spd_size = sys%n
   end function spd_size

   !> Half-bandwidth of the stored matrices in the RCM ordering (n - 1 when dense).
   pure integer function spd_bandwidth(sys)
      type(spd_system), intent(in) :: sys !! the system

      spd_bandwidth = sys%kb
   end function spd_bandwidth

   !> Whether the system is stored dense.
   pure logical function spd_is_dense(sys)
      type(spd_system), intent(in) :: sys !! the system

      spd_is_dense = sys%dense
   end function spd_is_dense

   !> Stiffness of device d in the current factor.
   pure real(dp) function spd_device_kd(sys, d)
      type(spd_system), intent(in) :: sys !! the system
      integer, intent(in) :: d            !! device

      spd_device_kd = sys%kd(d)
   end function spd_device_kd

   !> Largest estimated backward error that updates have added to the factor, relative to
   !> the pivots (0 after a fresh factorization; kept below the budget).
   pure real(dp) function spd_error_estimate(sys)
      type(spd_system), intent(in) :: sys !! the system

      spd_error_estimate = 0.0_dp
      if (sys%n > 0) spd_error_estimate = maxval(sys%errcol)
   end function spd_error_estimate

end module fd_banded
