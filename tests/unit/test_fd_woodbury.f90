!> Unit tests of the Woodbury solve of a factored effective stiffness plus a low-rank term
!> (fd_woodbury): (K^ + c U diag(d) U') x = b against an independent dense assembly factored
!> by LAPACK's dpotrf, on the dense and the banded storage of K^, after the factor changed
!> (devices stuck, then one freed), and the low-rank products against dense ones.
module test_fd_woodbury
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_error, only: lib_error => error_type
   use fd_linalg, only: cholesky_factor, cholesky_solve
   use fd_banded, only: spd_system, spd_setup, spd_factor, spd_update_devices, spd_solve, spd_is_dense, &
                        spd_dense, spd_banded
   use fd_woodbury, only: woodbury_type, woodbury_setup, woodbury_factor, woodbury_correct, lowrank_matvec, &
                          lowrank_form
   implicit none
   private

   public :: collect_woodbury

   real(dp), parameter :: h = 0.01_dp                     !! step of the Newmark coefficients
   real(dp), parameter :: c0 = 4.0_dp/h**2, c1 = 2.0_dp/h !! average acceleration

contains

   subroutine collect_woodbury(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("dense K^ plus low rank equals a dense solve", test_dense), &
                  new_unittest("banded K^ plus low rank equals a dense solve", test_banded), &
                  new_unittest("after the factor changes", test_refactor), &
                  new_unittest("low-rank products equal dense ones", test_products), &
                  new_unittest("a negative weight is refused", test_negative) &
                  ]
   end subroutine collect_woodbury

   !> A shear building of n storeys (a spring to the floor below) with a device beside each
   !> of its first nd storeys, Rayleigh a0, a1; U (n x r) a fixed smooth pattern with a
   !> weight d of each column, as modal damping's M phi_k would be.
   subroutine building(n, r, mass, si, sj, sk, ptr, dof, coef, u, d)
      integer, intent(in) :: n, r
      real(dp), allocatable, intent(out) :: mass(:), sk(:), coef(:), u(:, :), d(:)
      integer, allocatable, intent(out) :: si(:), sj(:), ptr(:), dof(:)
      integer :: i, k

      allocate (mass(n), sk(n), si(n), sj(n), u(n, r), d(r))
      do i = 1, n
         mass(i) = 1.0e3_dp*(1.0_dp + 0.1_dp*mod(i, 3))
         si(i) = i; sj(i) = i - 1
         sk(i) = 1.0e6_dp*(2.0_dp - real(i, dp)/real(n, dp))
         do k = 1, r
            u(i, k) = mass(i)*sin(real((2*k - 1)*i, dp)*acos(-1.0_dp)/real(2*n + 1, dp))
         end do
      end do
      do k = 1, r
         d(k) = 1.0e-5_dp*real(k, dp)
      end do
      ! devices in storeys 1 and 2: b = e_1 (to the table), b = e_2 - e_1
      ptr = [1, 2, 4]
      dof = [1, 2, 1]
      coef = [1.0_dp, 1.0_dp, -1.0_dp]
   end subroutine building

   !> The dense K^ + c1 (a0 M + a1 K) + c0 M + sum kd b b' + c1 U diag(d) U'.
   subroutine dense_system(n, mass, si, sj, sk, ptr, dof, coef, kd, a0, a1, u, d, a)
      integer, intent(in) :: n
      real(dp), intent(in) :: mass(:), sk(:), coef(:), kd(:), a0, a1, u(:, :), d(:)
      integer, intent(in) :: si(:), sj(:), ptr(:), dof(:)
      real(dp), intent(out) :: a(n, n)
      real(dp) :: k(n, n), b(n)
      integer :: s, i, j, dv

      k = 0.0_dp
      do s = 1, size(sk)
         i = si(s); j = sj(s)
         k(i, i) = k(i, i) + sk(s)
         if (j > 0) then
            k(j, j) = k(j, j) + sk(s)
            k(i, j) = k(i, j) - sk(s)
            k(j, i) = k(j, i) - sk(s)
         end if
      end do
      a = (1.0_dp + c1*a1)*k
      do i = 1, n
         a(i, i) = a(i, i) + (c0 + c1*a0)*mass(i)
      end do
      do dv = 1, size(kd)
         b = 0.0_dp
         do s = ptr(dv), ptr(dv + 1) - 1
            b(dof(s)) = coef(s)
         end do
         do j = 1, n
            a(:, j) = a(:, j) + kd(dv)*b*b(j)
         end do
      end do
      do s = 1, size(d)
         do j = 1, n
            a(:, j) = a(:, j) + c1*d(s)*u(j, s)*u(:, s)
         end do
      end do
   end subroutine dense_system

   !> The largest relative difference of the two solves of a right-hand side.
   subroutine compare(n, path, kd_change, err_max, dense_storage, error)
      integer, intent(in) :: n, path
      logical, intent(in) :: kd_change
      real(dp), intent(out) :: err_max
      logical, intent(out) :: dense_storage
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: mass(:), sk(:), coef(:), u(:, :), d(:), a(:, :), x(:), y(:), kd(:)
      integer, allocatable :: si(:), sj(:), ptr(:), dof(:)
      type(spd_system) :: sys
      type(woodbury_type) :: wb
      type(lib_error), allocatable :: lerr
      real(dp), parameter :: a0 = 0.2_dp, a1 = 1.0e-3_dp
      integer :: i, info

      call building(n, 4, mass, si, sj, sk, ptr, dof, coef, u, d)
      call spd_setup(sys, mass, si, sj, sk, ptr, dof, coef, lerr, a0=a0, a1=a1, path=path)
      call check(error, .not. allocated(lerr), "spd_setup")
      if (allocated(error)) return
      dense_storage = spd_is_dense(sys)
      kd = [5.0e7_dp, 5.0e7_dp]
      call spd_factor(sys, c0, c1, kd, lerr)
      call woodbury_setup(wb, u, d, c1, lerr)
      if (.not. allocated(lerr)) call woodbury_factor(wb, u, sys, lerr)
      if (kd_change .and. .not. allocated(lerr)) then
         ! the second device slips: its stiffness goes, the factor is updated, W follows
         kd(2) = 0.0_dp
         call spd_update_devices(sys, kd, lerr)
         if (.not. allocated(lerr)) call woodbury_factor(wb, u, sys, lerr)
      end if
      call check(error, .not. allocated(lerr), "factor")
      if (allocated(error)) return
      allocate (a(n, n), x(n), y(n))
      call dense_system(n, mass, si, sj, sk, ptr, dof, coef, kd, a0, a1, u, d, a)
      do i = 1, n
         x(i) = cos(0.7_dp*real(i, dp)) + 0.1_dp
      end do
      y = x
      call cholesky_factor(a, info)
      call check(error, info == 0, "dense factor")
      if (allocated(error)) return
      call cholesky_solve(a, x)
      call spd_solve(sys, y, lerr)
      call woodbury_correct(wb, u, y)
      err_max = maxval(abs(y - x))/maxval(abs(x))
   end subroutine compare

   subroutine test_dense(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: err
      logical :: dense

      call compare(6, spd_dense, .false., err, dense, error)
      if (allocated(error)) return
      call check(error, dense, "dense storage")
      if (allocated(error)) return
      call check(error, err < 1.0e-12_dp, "relative difference below 1e-12")
   end subroutine test_dense

   subroutine test_banded(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: err
      logical :: dense

      call compare(60, spd_banded, .false., err, dense, error)
      if (allocated(error)) return
      call check(error, .not. dense, "banded storage")
      if (allocated(error)) return
      call check(error, err < 1.0e-12_dp, "relative difference below 1e-12")
   end subroutine test_banded

   subroutine test_refactor(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: err
      logical :: dense

      call compare(60, spd_banded, .true., err, dense, error)
      if (allocated(error)) return
      call check(error, err < 1.0e-12_dp, "banded, a device freed: relative difference below 1e-12")
      if (allocated(error)) return
      call compare(6, spd_dense, .true., err, dense, error)
      if (allocated(error)) return
      call check(error, err < 1.0e-12_dp, "dense, a device freed: relative difference below 1e-12")
   end subroutine test_refactor

   subroutine test_products(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: mass(:), sk(:), coef(:), u(:, :), d(:)
      integer, allocatable :: si(:), sj(:), ptr(:), dof(:)
      real(dp) :: x(7), y(7), z(7), c(7, 7)
      integer :: i, j

      call building(7, 3, mass, si, sj, sk, ptr, dof, coef, u, d)
      c = 0.0_dp
      do i = 1, 3
         do j = 1, 7
            c(:, j) = c(:, j) + d(i)*u(j, i)*u(:, i)
         end do
      end do
      do i = 1, 7
         x(i) = real(i, dp) - 3.5_dp
         z(i) = sin(real(i, dp))
      end do
      y = 1.0_dp
      call lowrank_matvec(u, d, x, y, -2.0_dp)
      call check(error, maxval(abs(y - (1.0_dp - 2.0_dp*matmul(c, x)))) < 1.0e-12_dp*maxval(abs(y)), "matvec")
      if (allocated(error)) return
      call check(error, abs(lowrank_form(u, d, z, x) - dot_product(z, matmul(c, x))) < &
                 1.0e-12_dp*abs(dot_product(z, matmul(c, x))), "bilinear form")
   end subroutine test_products

   subroutine test_negative(error)
      type(error_type), allocatable, intent(out) :: error
      type(woodbury_type) :: wb
      type(lib_error), allocatable :: lerr
      real(dp) :: u(3, 2)

      u = 1.0_dp
      call woodbury_setup(wb, u, [1.0_dp, -1.0_dp], c1, lerr)
      call check(error, allocated(lerr), "a negative weight is an error")
      if (allocated(error)) return
      call check(error, index(lerr%message, 'negative') > 0, "the message says so")
   end subroutine test_negative

end module test_fd_woodbury
