!> Unit tests of the reduced band system of a sticking pattern (fd_group_system) against
!> dense T'(alpha M + beta K) T: solves on a chain (tridiagonal path) and a two-column frame
!> (band path, enlarged when a column sticks), the springs' K x, and the lowest eigenvalue
!> of the stuck system against LAPACK's dense generalized eigensolver.
module test_fd_group_system
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_error, only: fd_error_type => error_type
   use fd_rcm, only: rcm_order
   use fd_linalg, only: cholesky_factor, cholesky_solve, generalized_eigen
   use fd_stick_groups, only: edge_set, edges_setup, groups_build
   use fd_group_system, only: group_system, gs_setup, gs_factor, gs_solve, gs_k_matvec, gs_lowest_eigenvalue
   use test_fd_helpers, only: check_close
   use test_fd_mj_models, only: mj_model, rng_type, uniform, chain_model, frame_model, dense_w, dense_reduced
   implicit none
   private

   public :: collect_group_system

contains

   subroutine collect_group_system(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("chain: reduced solves equal dense", test_chain_solves), &
                  new_unittest("frame: reduced solves equal dense, band enlarged", test_frame_solves), &
                  new_unittest("K x over the springs equals dense", test_k_matvec), &
                  new_unittest("lowest eigenvalue equals dense dsygv", test_eigenvalue) &
                  ]
   end subroutine collect_group_system

   !> Random patterns: the band solve against the dense solve of T'W T; returns the band.
   subroutine compare_patterns(m, capacity, npat, seed, error, kbmax, growths)
      type(mj_model), intent(in) :: m
      integer, intent(in) :: capacity, npat, seed
      type(error_type), allocatable, intent(out) :: error
      integer, intent(out) :: kbmax, growths
      type(group_system) :: gs
      type(edge_set) :: es
      type(fd_error_type), allocatable :: err
      type(rng_type) :: rng
      real(dp), allocatable :: w(:, :), wr(:, :), b(:), x(:)
      logical, allocatable :: stuck(:)
      integer, allocatable :: order(:)
      integer :: k, info, e
      real(dp) :: alpha, beta

      rng%s = seed
      call edges_setup(es, m%n, m%di, m%dj, m%pmu, err)
      call check(error, .not. allocated(err), "edges")
      if (allocated(error)) return
      allocate (order(m%n), w(m%n, m%n), stuck(es%ne), b(m%n), x(m%n))
      call rcm_order(m%n, [m%si, m%di], [m%sj, m%dj], order)
      call gs_setup(gs, m%mass, m%si, m%sj, m%sk, capacity, err)
      call check(error, .not. allocated(err), "gs_setup")
      if (allocated(error)) return
      kbmax = 0
      do k = 1, npat
         do e = 1, es%ne
            stuck(e) = uniform(rng, 0.0_dp, 1.0_dp) < 0.5_dp
         end do
         if (k == 1) stuck = .true.
         alpha = uniform(rng, 0.5_dp, 2.0_dp)
         beta = uniform(rng, 0.0_dp, 1.0e-2_dp)
         call groups_build(es, stuck, order)
         call gs_factor(gs, es%grp, es%nr, alpha, beta, err)
         call check(error, .not. allocated(err), "factor")
         if (allocated(error)) return
         if (es%nr == 0) cycle
         kbmax = max(kbmax, gs%kb)
         call dense_w(m, alpha, beta, w)
         call dense_reduced(es%grp, es%nr, w, wr)
         do e = 1, es%nr
            b(e) = uniform(rng, -1.0_dp, 1.0_dp)
         end do
         x(1:es%nr) = b(1:es%nr)
         call gs_solve(gs, x)
         call cholesky_factor(wr, info)
         call cholesky_solve(wr, b(1:es%nr))
         call check_close(error, maxval(abs(x(1:es%nr) - b(1:es%nr))), 0.0_dp, &
                          1.0e-13_dp*maxval(abs(b(1:es%nr))), "band solve = dense solve", absolute=.true.)
         if (allocated(error)) return
      end do
      growths = gs%growths
   end subroutine compare_patterns

   subroutine test_chain_solves(error)
      type(error_type), allocatable, intent(out) :: error
      type(mj_model) :: m
      type(rng_type) :: rng
      integer :: kb, growths

      rng%s = 11
      call chain_model(rng, 30, m)
      call compare_patterns(m, 8, 40, 3, error, kb, growths)
      if (allocated(error)) return
      call check(error, kb <= 1, "a chain's reduced system stays tridiagonal, whatever sticks")
      if (allocated(error)) return
      call check(error, growths, 0, "no enlargement for a chain")
   end subroutine test_chain_solves

   subroutine test_frame_solves(error)
      type(error_type), allocatable, intent(out) :: error
      type(mj_model) :: m
      type(rng_type) :: rng
      integer :: kb, growths

      rng%s = 5
      call frame_model(rng, 20, m)
      ! all of column A stuck (the first pattern): one group beamed to every floor of B
      call compare_patterns(m, 2, 30, 9, error, kb, growths)
      if (allocated(error)) return
      call check(error, kb > 2, "a sticking column widens the band")
      if (allocated(error)) return
      call check(error, growths >= 1, "the storage was enlarged")
   end subroutine test_frame_solves

   subroutine test_k_matvec(error)
      type(error_type), allocatable, intent(out) :: error
      type(mj_model) :: m
      type(rng_type) :: rng
      type(group_system) :: gs
      type(fd_error_type), allocatable :: err
      real(dp), allocatable :: w(:, :), x(:), y(:)
      integer :: i

      rng%s = 2
      call frame_model(rng, 7, m)
      call gs_setup(gs, m%mass, m%si, m%sj, m%sk, 4, err)
      call check(error, .not. allocated(err), "gs_setup")
      if (allocated(error)) return
      allocate (w(m%n, m%n), x(m%n), y(m%n))
      call dense_w(m, 0.0_dp, 1.0_dp, w)
      do i = 1, m%n
         x(i) = uniform(rng, -1.0_dp, 1.0_dp)
         y(i) = uniform(rng, -1.0_dp, 1.0_dp)
      end do
      w(:, 1) = matmul(w, x)*2.0_dp - 3.0_dp*y     ! expected, kept in a spare column
      call gs_k_matvec(gs, x, y, 2.0_dp, -3.0_dp)
      call check_close(error, maxval(abs(y - w(:, 1))), 0.0_dp, 1.0e-13_dp*maxval(abs(y)), "2 K x - 3 y", &
                       absolute=.true.)
   end subroutine test_k_matvec

   !> The stuck frame (every device a rigid link) and a stuck chain with a free top.
   subroutine test_eigenvalue(error)
      type(error_type), allocatable, intent(out) :: error
      type(mj_model) :: m
      type(rng_type) :: rng
      type(group_system) :: gs
      type(edge_set) :: es
      type(fd_error_type), allocatable :: err
      real(dp), allocatable :: k(:, :), mm(:, :), kr(:, :), mr(:, :), lam(:), phi(:, :)
      integer, allocatable :: order(:)
      real(dp) :: low, scale
      integer :: trial, i

      do trial = 1, 2
         rng%s = 17 + trial
         if (trial == 1) then
            call frame_model(rng, 9, m)
         else
            call chain_model(rng, 25, m)
            m%pmu(20) = 0.0_dp      ! storeys 20-22 and 23-25 move, two groups
            m%pmu(23) = 0.0_dp
         end if
         call edges_setup(es, m%n, m%di, m%dj, m%pmu, err)
         call check(error, .not. allocated(err), "edges")
         if (allocated(error)) return
         if (allocated(order)) deallocate (order, k, mm)
         allocate (order(m%n), k(m%n, m%n), mm(m%n, m%n))
         call rcm_order(m%n, [m%si, m%di], [m%sj, m%dj], order)
         call groups_build(es, [(.true., i=1, es%ne)], order)
         call gs_setup(gs, m%mass, m%si, m%sj, m%sk, 2, err)
         call check(error, .not. allocated(err), "gs_setup")
         if (allocated(error)) return
         call gs_lowest_eigenvalue(gs, es%grp, es%nr, low, scale, err)
         call check(error, .not. allocated(err), "dsbgvx")
         if (allocated(error)) return
         call dense_w(m, 0.0_dp, 1.0_dp, k)
         call dense_w(m, 1.0_dp, 0.0_dp, mm)
         call dense_reduced(es%grp, es%nr, k, kr)
         call dense_reduced(es%grp, es%nr, mm, mr)
         if (allocated(lam)) deallocate (lam, phi)
         allocate (lam(es%nr), phi(es%nr, es%nr))
         call generalized_eigen(kr, mr, lam, phi, err)
         call check(error, .not. allocated(err), "dsygv")
         if (allocated(error)) return
         call check_close(error, low, lam(1), 1.0e-12_dp, "lowest eigenvalue of the stuck system")
         if (allocated(error)) return
         call check(error, scale >= 0.5_dp*lam(es%nr), "its scale bounds the spectrum")
         if (allocated(error)) return
      end do
   end subroutine test_eigenvalue

end module test_fd_group_system
