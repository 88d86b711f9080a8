!> Unit tests of the sparse effective stiffness (fd_sparse, CHOLMOD through fd_cholmod.c):
!> K^ = K + c1 C + c0 M + sum kd b b' of a plan grid of springs (one DOF a node, a wide band
!> after ordering) with devices between two nodes, to the table and of three terms, solved
!> against an independent dense assembly factored by LAPACK; after devices change stiffness
!> (the Woodbury terms, and a refactorization past their limit); the products K x and C x
!> against dense ones; several right-hand sides at once; changes and solves interleaved; a K^ that
!> is not positive definite named by its DOF. Skipped when the build has no CHOLMOD (then
!> set-up is an error saying so).
module test_fd_sparse
   use testdrive, only: new_unittest, unittest_type, error_type, check, skip_test
   use fd_kinds, only: dp
   use fd_error, only: lib_error => error_type
   use fd_linalg, only: cholesky_factor, cholesky_solve
   use fd_sparse, only: sparse_system, sparse_available, sparse_setup, sparse_factor, sparse_update_devices, &
                        sparse_solve, sparse_solve_many, sparse_k_matvec, sparse_c_matvec, sparse_kc_matvec, &
                        sparse_free, sparse_band, sparse_factor_entries
   implicit none
   private

   public :: collect_sparse

   real(dp), parameter :: h = 0.01_dp                     !! step of the Newmark coefficients
   real(dp), parameter :: c0 = 4.0_dp/h**2, c1 = 2.0_dp/h !! average acceleration
   real(dp), parameter :: a0 = 0.2_dp, a1 = 1.0e-3_dp     !! Rayleigh damping
   integer, parameter :: m = 12                           !! nodes along a side of the grid
   integer, parameter :: n = m*m

   !> The grid: springs, K_x, devices.
   type :: grid_type
      real(dp), allocatable :: mass(:), sk(:), coef(:), kxv(:)
      integer, allocatable :: si(:), sj(:), ptr(:), dof(:), kxi(:), kxj(:)
   end type grid_type

contains

   subroutine collect_sparse(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("solve equals a dense solve", test_solve), &
                  new_unittest("device changes by Woodbury equal a dense solve", test_changes), &
                  new_unittest("many changes refactor and equal a dense solve", test_many_changes), &
                  new_unittest("products K x, C x equal dense ones", test_products), &
                  new_unittest("several right-hand sides at once", test_many_rhs), &
                  new_unittest("interleaved changes and solves stay the dense solve", test_interleaved), &
                  new_unittest("not positive definite names its DOF", test_indefinite), &
                  new_unittest("the band of a plan grid is its side", test_band), &
                  new_unittest("without CHOLMOD set-up says so", test_unavailable) &
                  ]
   end subroutine collect_sparse

   !> An m x m grid of springs between neighbours (node (i, j) = i + m (j - 1)), the first row
   !> to the table; K_x: a spring between opposite corners; devices: 12 between neighbours,
   !> one to the table, one of three terms (b = e_p - (e_q + e_r) / 2).
   subroutine grid(g)
      type(grid_type), intent(out) :: g
      integer :: i, j, k, p

      allocate (g%mass(n), g%si(0), g%sj(0), g%sk(0))
      do j = 1, m
         do i = 1, m
            p = i + m*(j - 1)
            g%mass(p) = 1.0e3_dp*(1.0_dp + 0.1_dp*mod(p, 7))
            if (i < m) call spring(p, p + 1, 2.0e6_dp*(1.0_dp + 0.05_dp*mod(p, 5)))
            if (j < m) call spring(p, p + m, 1.5e6_dp*(1.0_dp + 0.03_dp*mod(p, 4)))
            if (j == 1) call spring(p, 0, 3.0e6_dp)
         end do
      end do
      g%kxi = [1]
      g%kxj = [n]
      g%kxv = [-1.0e5_dp]
      g%ptr = [1]
      g%dof = [integer ::]
      g%coef = [real(dp) ::]
      do k = 1, 12
         p = 1 + mod(11*k, n - m)
         g%dof = [g%dof, p, p + m]
         g%coef = [g%coef, 1.0_dp, -1.0_dp]
         g%ptr = [g%ptr, size(g%dof) + 1]
      end do
      g%dof = [g%dof, n/2, 3, n - 2, n - 1]
      g%coef = [g%coef, 1.0_dp, 1.0_dp, -0.5_dp, -0.5_dp]
      g%ptr = [g%ptr, size(g%dof) - 2, size(g%dof) + 1]
      ! K_x's corner spring: its diagonal terms too
      g%kxi = [g%kxi, 1, n]
      g%kxj = [g%kxj, 1, n]
      g%kxv = [g%kxv, 1.0e5_dp, 1.0e5_dp]
   contains
      subroutine spring(a, b, k)
         integer, intent(in) :: a, b
         real(dp), intent(in) :: k
         g%si = [g%si, a]
         g%sj = [g%sj, b]
         g%sk = [g%sk, k]
      end subroutine spring
   end subroutine grid

   !> The dense K (springs and K_x).
   subroutine dense_k(g, k)
      type(grid_type), intent(in) :: g
      real(dp), intent(out) :: k(n, n)
      integer :: s, i, j

      k = 0.0_dp
      do s = 1, size(g%sk)
         i = g%si(s); j = g%sj(s)
         k(i, i) = k(i, i) + g%sk(s)
         if (j > 0) then
            k(j, j) = k(j, j) + g%sk(s)
            k(i, j) = k(i, j) - g%sk(s)
            k(j, i) = k(j, i) - g%sk(s)
         end if
      end do
      do s = 1, size(g%kxv)
         i = g%kxi(s); j = g%kxj(s)
         k(i, j) = k(i, j) + g%kxv(s)
         if (i /= j) k(j, i) = k(j, i) + g%kxv(s)
      end do
   end subroutine dense_k

   !> The dense K^ for device stiffnesses kd.
   subroutine dense_system(g, kd, a)
      type(grid_type), intent(in) :: g
      real(dp), intent(in) :: kd(:)
      real(dp), intent(out) :: a(n, n)
      real(dp) :: b(n)
      integer :: i, j, s, dv

      call dense_k(g, a)
      a = (1.0_dp + c1*a1)*a
      do i = 1, n
         a(i, i) = a(i, i) + (c0 + c1*a0)*g%mass(i)
      end do
      do dv = 1, size(kd)
         b = 0.0_dp
         do s = g%ptr(dv), g%ptr(dv + 1) - 1
            b(g%dof(s)) = b(g%dof(s)) + g%coef(s)
         end do
         do j = 1, n
            a(:, j) = a(:, j) + kd(dv)*b*b(j)
         end do
      end do
   end subroutine dense_system

   subroutine setup(g, sys, error)
      type(grid_type), intent(out) :: g
      type(sparse_system), intent(inout) :: sys
      type(error_type), allocatable, intent(out) :: error
      type(lib_error), allocatable :: lerr
      integer :: none(0)

      if (.not. sparse_available()) then
         call skip_test(error, "the build has no CHOLMOD")
         return
      end if
      call grid(g)
      call sparse_setup(sys, g%mass, g%si, g%sj, g%sk, g%ptr, g%dof, g%coef, a0, a1, none, none, [real(dp) ::], &
                        lerr, g%kxi, g%kxj, g%kxv)
      call check(error, .not. allocated(lerr), "sparse_setup")
   end subroutine setup

   !> The largest difference of the sparse solve from the dense one, relative to the solution.
   subroutine solve_error(g, sys, kd, err, error)
      type(grid_type), intent(in) :: g
      type(sparse_system), intent(inout) :: sys
      real(dp), intent(in) :: kd(:)
      real(dp), intent(out) :: err
      type(error_type), allocatable, intent(out) :: error
      type(lib_error), allocatable :: lerr
      real(dp) :: a(n, n), x(n), y(n)
      integer :: i, info

      do i = 1, n
         x(i) = cos(0.7_dp*real(i, dp)) + 0.1_dp
      end do
      y = x
      call sparse_solve(sys, x, lerr)
      call check(error, .not. allocated(lerr), "sparse_solve")
      if (allocated(error)) return
      call dense_system(g, kd, a)
      call cholesky_factor(a, info)
      call check(error, info, 0, "dense factor")
      if (allocated(error)) return
      call cholesky_solve(a, y)
      err = maxval(abs(x - y))/maxval(abs(y))
   end subroutine solve_error

   subroutine test_solve(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: g
      type(sparse_system) :: sys
      type(lib_error), allocatable :: lerr
      real(dp) :: kd(14), err

      call setup(g, sys, error)
      if (allocated(error)) return
      kd = 5.0e7_dp
      kd(3) = 0.0_dp
      call sparse_factor(sys, c0, c1, kd, lerr)
      call check(error, .not. allocated(lerr), "sparse_factor")
      if (.not. allocated(error)) call solve_error(g, sys, kd, err, error)
      if (.not. allocated(error)) call check(error, err < 1.0e-13_dp, "relative error above 1e-13")
      if (.not. allocated(error)) call check(error, sparse_factor_entries(sys) > real(n, dp), "factor entries")
      if (allocated(error)) return
      ! a system set up again starts afresh (its arrays and CHOLMOD's handle replaced)
      call setup(g, sys, error)
      if (allocated(error)) return
      call sparse_factor(sys, c0, c1, kd, lerr)
      call check(error, .not. allocated(lerr), "sparse_factor after a second set-up")
      if (.not. allocated(error)) call solve_error(g, sys, kd, err, error)
      if (.not. allocated(error)) call check(error, err < 1.0e-13_dp, "relative error above 1e-13")
      call sparse_free(sys)
   end subroutine test_solve

   !> Devices stuck (5e7), then three freed and one stiffened: the factor is kept, the
   !> changes go by the Woodbury identity (no new factorization), the solve is the dense one's.
   subroutine test_changes(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: g
      type(sparse_system) :: sys
      type(lib_error), allocatable :: lerr
      real(dp) :: kd(14), err

      call setup(g, sys, error)
      if (allocated(error)) return
      kd = 5.0e7_dp
      call sparse_factor(sys, c0, c1, kd, lerr)
      kd([2, 7, 13]) = 0.0_dp
      kd(14) = 2.0e8_dp
      if (.not. allocated(lerr)) call sparse_update_devices(sys, kd, lerr)
      call check(error, .not. allocated(lerr), "update")
      if (allocated(error)) return
      call check(error, sys%factorizations, 1, "refactored")
      if (allocated(error)) return
      call check(error, sys%ns, 4, "changed devices")
      if (allocated(error)) return
      call solve_error(g, sys, kd, err, error)
      if (.not. allocated(error)) call check(error, err < 1.0e-12_dp, "relative error above 1e-12")
      if (allocated(error)) return
      ! two of them back to the factored stiffness: their terms go
      kd([2, 14]) = 5.0e7_dp
      call sparse_update_devices(sys, kd, lerr)
      call check(error, .not. allocated(lerr), "update")
      if (.not. allocated(error)) call check(error, sys%ns, 2, "changed devices")
      if (.not. allocated(error)) call solve_error(g, sys, kd, err, error)
      if (.not. allocated(error)) call check(error, err < 1.0e-12_dp, "relative error above 1e-12")
      call sparse_free(sys)
   end subroutine test_changes

   !> Every device changed: more than the Woodbury terms take, so K^ is factored again.
   subroutine test_many_changes(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: g
      type(sparse_system) :: sys
      type(lib_error), allocatable :: lerr
      real(dp) :: kd(14), err
      integer :: k

      call setup(g, sys, error)
      if (allocated(error)) return
      kd = 0.0_dp
      call sparse_factor(sys, c0, c1, kd, lerr)
      kd = [(1.0e7_dp*k, k=1, 14)]
      if (.not. allocated(lerr)) call sparse_update_devices(sys, kd, lerr)
      call check(error, .not. allocated(lerr), "update")
      if (allocated(error)) return
      ! smax = nnz(L) / n, at most the devices: the grid's factor has fewer than 14 a column
      if (sys%ns == 0) then
         call check(error, sys%factorizations, 2, "factorizations")
      else
         call check(error, sys%ns, 14, "changed devices")
      end if
      if (.not. allocated(error)) call solve_error(g, sys, kd, err, error)
      if (.not. allocated(error)) call check(error, err < 1.0e-12_dp, "relative error above 1e-12")
      call sparse_free(sys)
   end subroutine test_many_changes

   subroutine test_products(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: g
      type(sparse_system) :: sys
      real(dp) :: k(n, n), x(n), v(n), y(n), z(n), cm(n, n)
      integer :: i

      call setup(g, sys, error)
      if (allocated(error)) return
      call dense_k(g, k)
      cm = a1*k
      do i = 1, n
         cm(i, i) = cm(i, i) + a0*g%mass(i)
         x(i) = sin(0.3_dp*real(i, dp))
         v(i) = cos(0.2_dp*real(i, dp))
      end do
      y = 1.0_dp
      call sparse_k_matvec(sys, x, y, -2.0_dp, 0.5_dp)
      z = 0.5_dp - 2.0_dp*matmul(k, x)
      call check(error, maxval(abs(y - z)) < 1.0e-12_dp*maxval(abs(z)), "K x")
      if (allocated(error)) return
      y = 1.0_dp
      call sparse_c_matvec(sys, v, y, 3.0_dp, 1.0_dp)
      z = 1.0_dp + 3.0_dp*matmul(cm, v)
      call check(error, maxval(abs(y - z)) < 1.0e-12_dp*maxval(abs(z)), "C v")
      if (allocated(error)) return
      y = 1.0_dp
      call sparse_kc_matvec(sys, x, v, y, -1.0_dp)
      z = 1.0_dp - matmul(k, x) - matmul(cm, v)
      call check(error, maxval(abs(y - z)) < 1.0e-12_dp*maxval(abs(z)), "K x + C v")
      call sparse_free(sys)
   end subroutine test_products

   subroutine test_many_rhs(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: g
      type(sparse_system) :: sys
      type(lib_error), allocatable :: lerr
      real(dp) :: kd(14), x(n, 3), y(n)
      integer :: i, j

      call setup(g, sys, error)
      if (allocated(error)) return
      kd = 1.0e7_dp
      call sparse_factor(sys, c0, c1, kd, lerr)
      do j = 1, 3
         do i = 1, n
            x(i, j) = cos(0.1_dp*real(i*j, dp))
         end do
      end do
      if (.not. allocated(lerr)) call sparse_solve_many(sys, x, lerr)
      call check(error, .not. allocated(lerr), "solve")
      do j = 1, 3
         if (allocated(error)) exit
         do i = 1, n
            y(i) = cos(0.1_dp*real(i*j, dp))
         end do
         call sparse_solve(sys, y, lerr)
         call check(error, maxval(abs(x(:, j) - y)) <= 1.0e-14_dp*maxval(abs(y)), "column differs")
      end do
      call sparse_free(sys)
   end subroutine test_many_rhs

   !> Fifty steps of device changes, refactorizations every ten and solves of one and of three
   !> columns in turn (as a run's steps and phase changes interleave them): the last state's
   !> solve is still the dense one's (the solve's work vector reused throughout).
   subroutine test_interleaved(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: g
      type(sparse_system) :: sys
      type(lib_error), allocatable :: lerr
      real(dp) :: kd(14), x(n), xs(n, 3), err
      integer :: k

      call setup(g, sys, error)
      if (allocated(error)) return
      kd = 1.0e7_dp
      call sparse_factor(sys, c0, c1, kd, lerr)
      x = 1.0_dp
      xs = 1.0_dp
      do k = 1, 50
         if (allocated(lerr)) exit
         kd(1 + mod(k, 14)) = 1.0e7_dp*mod(k, 3)
         if (mod(k, 10) == 0) call sparse_factor(sys, c0, c1, kd, lerr)
         if (.not. allocated(lerr)) call sparse_update_devices(sys, kd, lerr)
         if (.not. allocated(lerr)) call sparse_solve(sys, x, lerr)
         if (.not. allocated(lerr) .and. mod(k, 2) == 0) call sparse_solve_many(sys, xs, lerr)
      end do
      call check(error, .not. allocated(lerr), "solve")
      if (.not. allocated(error)) call solve_error(g, sys, kd, err, error)
      if (.not. allocated(error)) call check(error, err < 1.0e-12_dp, "relative error above 1e-12")
      call sparse_free(sys)
   end subroutine test_interleaved

   !> K_x's diagonal at DOF 40 so negative that K^ is indefinite there: the factorization
   !> fails at that DOF (every principal submatrix without it is positive definite).
   subroutine test_indefinite(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: g
      type(sparse_system) :: sys
      type(lib_error), allocatable :: lerr
      real(dp) :: kd(14)
      integer :: none(0)

      if (.not. sparse_available()) then
         call skip_test(error, "the build has no CHOLMOD")
         return
      end if
      call grid(g)
      g%kxi = [g%kxi, 40]
      g%kxj = [g%kxj, 40]
      g%kxv = [g%kxv, -1.0e12_dp]
      call sparse_setup(sys, g%mass, g%si, g%sj, g%sk, g%ptr, g%dof, g%coef, a0, a1, none, none, [real(dp) ::], &
                        lerr, g%kxi, g%kxj, g%kxv)
      call check(error, .not. allocated(lerr), "sparse_setup")
      if (allocated(error)) return
      kd = 0.0_dp
      call sparse_factor(sys, c0, c1, kd, lerr)
      call check(error, allocated(lerr), "an indefinite K^ factored")
      if (.not. allocated(error)) call check(error, index(lerr%message, "not positive definite") > 0 .and. &
                                             index(lerr%message, "DOF 40") > 0, lerr%message)
      call sparse_free(sys)
   end subroutine test_indefinite

   !> Reverse Cuthill-McKee on an m x m grid: a band of m (the grid's diagonals are its levels).
   subroutine test_band(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: g
      integer :: none(0), kb

      call grid(g)
      kb = sparse_band(n, g%si, g%sj, [1], none, none, none)
      call check(error, kb >= m - 1 .and. kb <= m + 1, "band of the grid")
   end subroutine test_band

   subroutine test_unavailable(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: g
      type(sparse_system) :: sys
      type(lib_error), allocatable :: lerr
      integer :: none(0)

      if (sparse_available()) then
         call skip_test(error, "the build has CHOLMOD")
         return
      end if
      call grid(g)
      call sparse_setup(sys, g%mass, g%si, g%sj, g%sk, g%ptr, g%dof, g%coef, a0, a1, none, none, [real(dp) ::], &
                        lerr, g%kxi, g%kxj, g%kxv)
      call check(error, allocated(lerr), "set-up without CHOLMOD")
      if (.not. allocated(error)) call check(error, index(lerr%message, "no sparse solver (CHOLMOD)") > 0, &
                                             lerr%message)
   end subroutine test_unavailable

end module test_fd_sparse
