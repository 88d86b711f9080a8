!> Unit tests of planar Coulomb friction in the Moreau-Jean one-step problem (fd_disc_solver):
!> one bearing's local problem against its closed form (isotropic block) and against the law
!> itself (anisotropic block: |lambda| = g, lambda along w, to 1e-12), stick and slip; several
!> bearings and 1D devices by block Gauss-Seidel against Lemke's method (1D devices alone) and
!> the law on every block; the cap on the sweeps reported.
module test_fd_disc_solver
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_disc_solver, only: disc_local, disc_gauss_seidel, disc_ok, disc_not_definite, disc_unconverged
   use fd_lcp, only: lcp_work, lcp_info, lcp_init, box_lcp_solve, lcp_solved
   use fd_error, only: fd_error_type => error_type
   use test_fd_helpers, only: check_close
   implicit none
   private

   public :: collect_disc_solver

   !> an anisotropic, coupled block (eigenvalues 1.2 and 3.8 about 30 degrees)
   real(dp), parameter :: aniso(2, 2) = reshape([1.85_dp, 1.1258330249197703_dp, 1.1258330249197703_dp, &
                                                 3.15_dp], [2, 2])

contains

   subroutine collect_disc_solver(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("isotropic slip: lambda = g c/|c|, w = c - a g c/|c|", test_iso_slip), &
                  new_unittest("isotropic stick: lambda = c / a, w = 0", test_iso_stick), &
                  new_unittest("anisotropic slip: the law to 1e-12", test_aniso_slip), &
                  new_unittest("anisotropic stick: w = 0, lambda inside the disc", test_aniso_stick), &
                  new_unittest("c along an axis of a diagonal block: the 1D law exactly", test_axis), &
                  new_unittest("a block not positive definite is reported", test_not_definite), &
                  new_unittest("Gauss-Seidel, 1D devices alone: Lemke's solution", test_gs_lemke), &
                  new_unittest("Gauss-Seidel, bearings and 1D devices: the law on every block", test_gs_mixed), &
                  new_unittest("Gauss-Seidel: the cap on the sweeps is reported", test_gs_cap) &
                  ]
   end subroutine collect_disc_solver

   !> The planar law's residual: |lambda| <= g, and w = 0 or lambda = g w / |w|, relative to
   !> the scales g and |c|.
   subroutine check_law(error, lam, w, c, g, tol, what)
      type(error_type), allocatable, intent(out) :: error
      real(dp), intent(in) :: lam(2), w(2), c(2), g, tol
      character(len=*), intent(in) :: what
      real(dp) :: nl, nw

      nl = hypot(lam(1), lam(2))
      nw = hypot(w(1), w(2))
      call check(error, nl <= g*(1.0_dp + tol), what//': |lambda| <= g')
      if (allocated(error)) return
      if (nw <= tol*hypot(c(1), c(2))) return
      call check_close(error, nl, g, tol, what//': |lambda| = g while sliding')
      if (allocated(error)) return
      call check_close(error, hypot(lam(1)/g - w(1)/nw, lam(2)/g - w(2)/nw), 0.0_dp, tol, &
                       what//': lambda along w', absolute=.true.)
   end subroutine check_law

   subroutine test_iso_slip(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(2, 2), c(2), lam(2), w(2), g, nc
      integer :: status

      a = reshape([2.5_dp, 0.0_dp, 0.0_dp, 2.5_dp], [2, 2])
      c = [0.3_dp, -0.4_dp]
      g = 0.1_dp
      nc = 0.5_dp
      call disc_local(a, c, g, lam, w, status)
      call check(error, status == disc_ok, 'status')
      if (allocated(error)) return
      call check_close(error, lam(1), g*c(1)/nc, 1.0e-15_dp, 'lambda x')
      if (allocated(error)) return
      call check_close(error, lam(2), g*c(2)/nc, 1.0e-15_dp, 'lambda y')
      if (allocated(error)) return
      ! |w| = |c| - a g along c
      call check_close(error, w(1), c(1)*(1.0_dp - 2.5_dp*g/nc), 1.0e-14_dp, 'w x')
      if (allocated(error)) return
      call check_close(error, w(2), c(2)*(1.0_dp - 2.5_dp*g/nc), 1.0e-14_dp, 'w y')
   end subroutine test_iso_slip

   subroutine test_iso_stick(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(2, 2), c(2), lam(2), w(2)
      integer :: status

      a = reshape([2.5_dp, 0.0_dp, 0.0_dp, 2.5_dp], [2, 2])
      c = [0.12_dp, -0.16_dp]   ! |c| / a = 0.08 < g
      call disc_local(a, c, 0.1_dp, lam, w, status)
      call check(error, status == disc_ok, 'status')
      if (allocated(error)) return
      call check_close(error, lam(1), 0.048_dp, 1.0e-15_dp, 'lambda x')
      if (allocated(error)) return
      call check_close(error, lam(2), -0.064_dp, 1.0e-15_dp, 'lambda y')
      if (allocated(error)) return
      call check(error, w(1) == 0.0_dp .and. w(2) == 0.0_dp, 'w = 0 exactly')
   end subroutine test_iso_stick

   subroutine test_aniso_slip(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: c(2), lam(2), w(2), g, th
      integer :: status, k

      g = 0.2_dp
      ! directions all round, |A^-1 c| well outside and just outside the disc
      do k = 0, 11
         th = k*0.5235987755982988_dp + 0.1_dp
         c = merge(3.0_dp, 0.9_dp, mod(k, 2) == 0)*[cos(th), sin(th)]
         call disc_local(aniso, c, g, lam, w, status)
         call check(error, status == disc_ok, 'status')
         if (allocated(error)) return
         call check(error, hypot(w(1), w(2)) > 1.0e-3_dp, 'it slides')
         if (allocated(error)) return
         call check_law(error, lam, w, c, g, 1.0e-12_dp, 'anisotropic slip')
         if (allocated(error)) return
         ! w = c - A lambda, the velocity the impulse leaves
         call check_close(error, hypot(w(1) - (c(1) - aniso(1, 1)*lam(1) - aniso(1, 2)*lam(2)), &
                                       w(2) - (c(2) - aniso(2, 1)*lam(1) - aniso(2, 2)*lam(2))), 0.0_dp, &
                          1.0e-15_dp, 'w = c - A lambda', absolute=.true.)
         if (allocated(error)) return
      end do
   end subroutine test_aniso_slip

   subroutine test_aniso_stick(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: c(2), lam(2), w(2)
      integer :: status

      c = [0.3_dp, 0.2_dp]
      call disc_local(aniso, c, 1.0_dp, lam, w, status)
      call check(error, status == disc_ok, 'status')
      if (allocated(error)) return
      call check(error, hypot(lam(1), lam(2)) < 1.0_dp, 'inside the disc')
      if (allocated(error)) return
      call check_close(error, hypot(w(1), w(2)), 0.0_dp, 1.0e-15_dp, 'w = 0', absolute=.true.)
   end subroutine test_aniso_stick

   !> A diagonal block and c along x: the x component is the 1D law bit for bit, y stays 0.
   subroutine test_axis(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(2, 2), lam(2), w(2)
      integer :: status

      a = reshape([1.7_dp, 0.0_dp, 0.0_dp, 4.1_dp], [2, 2])
      call disc_local(a, [-0.9_dp, 0.0_dp], 0.3_dp, lam, w, status)
      call check(error, status == disc_ok .and. lam(1) == -0.3_dp .and. lam(2) == 0.0_dp, 'slip: -g, 0')
      if (allocated(error)) return
      call check(error, w(1) == -0.9_dp + 1.7_dp*0.3_dp .and. w(2) == 0.0_dp, 'slip: w')
      if (allocated(error)) return
      call disc_local(a, [0.34_dp, 0.0_dp], 0.3_dp, lam, w, status)
      call check(error, lam(1) == 0.34_dp/1.7_dp .and. lam(2) == 0.0_dp, 'stick: c / a, 0')
   end subroutine test_axis

   subroutine test_not_definite(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: lam(2), w(2)
      integer :: status

      call disc_local(reshape([1.0_dp, 1.0_dp, 1.0_dp, 1.0_dp], [2, 2]), [1.0_dp, 0.0_dp], 0.1_dp, lam, w, &
                      status)
      call check(error, status == disc_not_definite, 'a singular block')
   end subroutine test_not_definite

   !> A symmetric positive definite operator of m devices (L L' + I / 2 of a fixed L).
   subroutine operator_of(m, a)
      integer, intent(in) :: m
      real(dp), intent(out) :: a(m, m)
      real(dp) :: l(m, m)
      integer :: i, j

      do j = 1, m
         do i = 1, m
            l(i, j) = sin(1.3_dp*i + 0.7_dp*j*j)
         end do
      end do
      a = 0.3_dp*matmul(l, transpose(l))
      do i = 1, m
         a(i, i) = a(i, i) + 0.5_dp
      end do
   end subroutine operator_of

   subroutine test_gs_lemke(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: m = 6
      real(dp) :: a(m, m), q(m), g(m), lam(m), w(m), z(m), ww(m), change
      integer :: sweeps, status, i
      type(lcp_work) :: work
      type(lcp_info) :: info
      type(fd_error_type), allocatable :: err

      call operator_of(m, a)
      q = [(2.0_dp*cos(2.1_dp*i), i=1, m)]
      g = [(0.3_dp + 0.1_dp*i, i=1, m)]
      lam = 0.0_dp
      call disc_gauss_seidel(a, q, g, [(0, i=1, m)], 1.0e-14_dp, 10000, lam, w, sweeps, change, status)
      call check(error, status == disc_ok, 'converged')
      if (allocated(error)) return
      call lcp_init(work, m, m, err)
      call box_lcp_solve(work, a, -q, -g, g, z, ww, info)
      call check(error, info%status == lcp_solved, 'Lemke')
      if (allocated(error)) return
      call check(error, count(abs(lam) < g*(1.0_dp - 1.0e-9_dp)) >= 1 .and. count(abs(lam) >= g) >= 1, &
                 'some devices stick, some slide')
      if (allocated(error)) return
      do i = 1, m
         call check_close(error, lam(i), z(i), 1.0e-11_dp*maxval(g), 'lambda against Lemke', absolute=.true.)
         if (allocated(error)) return
      end do
   end subroutine test_gs_lemke

   subroutine test_gs_mixed(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: m = 7
      real(dp) :: a(m, m), q(m), g(m), lam(m), w(m), change, c(2)
      integer :: partner(m), sweeps, status, i, j, n_slide, n_stick

      call operator_of(m, a)
      q = [(1.5_dp*cos(2.1_dp*i), i=1, m)]
      ! bearings (1, 2), (4, 5), (6, 7); device 3 one-dimensional
      partner = [2, 1, 0, 5, 4, 7, 6]
      g = [0.4_dp, 0.4_dp, 0.2_dp, 0.05_dp, 0.05_dp, 3.0_dp, 3.0_dp]
      lam = 0.0_dp
      call disc_gauss_seidel(a, q, g, partner, 1.0e-14_dp, 10000, lam, w, sweeps, change, status)
      call check(error, status == disc_ok, 'converged')
      if (allocated(error)) return
      call check(error, sweeps > 2, 'the blocks are coupled')
      if (allocated(error)) return
      n_slide = 0
      n_stick = 0
      do i = 1, m
         j = partner(i)
         if (j == 0 .or. j < i) cycle
         c = [q(i) - dot_product(a(i, :), lam) + a(i, i)*lam(i) + a(i, j)*lam(j), &
              q(j) - dot_product(a(j, :), lam) + a(j, i)*lam(i) + a(j, j)*lam(j)]
         call check_law(error, lam([i, j]), w([i, j]), c, g(i), 1.0e-10_dp, 'bearing')
         if (allocated(error)) return
         if (hypot(w(i), w(j)) > 1.0e-6_dp) n_slide = n_slide + 1
         if (hypot(w(i), w(j)) <= 1.0e-12_dp) n_stick = n_stick + 1
      end do
      call check(error, n_slide >= 1 .and. n_stick >= 1, 'a bearing slides and one sticks')
      if (allocated(error)) return
      ! the 1D device: clipped
      call check(error, abs(lam(3)) <= g(3), '1D bound')
      if (allocated(error)) return
      if (abs(lam(3)) < g(3)) then
         call check_close(error, w(3), 0.0_dp, 1.0e-10_dp, '1D stick', absolute=.true.)
      else
         call check(error, w(3)*lam(3) >= 0.0_dp, '1D slides its impulse''s way')
      end if
   end subroutine test_gs_mixed

   subroutine test_gs_cap(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: m = 4
      real(dp) :: a(m, m), q(m), g(m), lam(m), w(m), change
      integer :: sweeps, status

      call operator_of(m, a)
      q = [0.1_dp, -0.2_dp, 0.15_dp, 0.05_dp]
      g = 10.0_dp
      lam = 0.0_dp
      call disc_gauss_seidel(a, q, g, [2, 1, 4, 3], 1.0e-14_dp, 2, lam, w, sweeps, change, status)
      call check(error, status == disc_unconverged .and. sweeps == 2 .and. change > 1.0e-14_dp, &
                 'unconverged after the cap')
   end subroutine test_gs_cap

end module test_fd_disc_solver
