!> Unit tests of the lowest natural modes (fd_modes): the subspace iteration with the banded
!> factor against the closed form of a uniform chain and against LAPACK's dense dsygv on
!> randomly numbered chains and a plane frame; the mode shapes M-normalized, K-orthogonal,
!> and the residual of K phi = lambda M phi at round-off; a structure with a rigid-body mode
!> recognised (lambda ~ 0 against the scale of the spectrum). The highest eigenvalue
!> (highest_eigenvalue: Lanczos, with Gershgorin's bound) against closed forms and dsygv. The
!> general forms (K_x entries, device directions as constraints or sticking springs) against
!> the closed form of a chain held at both ends.
module test_fd_modes
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_error, only: lib_error => error_type
   use fd_modes, only: lowest_modes, modes_dense, modes_iterative, highest_eigenvalue, general_lowest_modes, &
                       general_highest_eigenvalue
   use test_fd_helpers, only: check_close
   implicit none
   private

   public :: collect_modes

   real(dp), parameter :: pi = acos(-1.0_dp)

contains

   subroutine collect_modes(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("uniform chain closed form", test_chain_closed_form), &
                  new_unittest("iterative equals dense", test_against_dense), &
                  new_unittest("frame modes and residuals", test_frame), &
                  new_unittest("rigid-body mode has lambda ~ 0", test_rigid), &
                  new_unittest("highest eigenvalue: two masses, closed form", test_highest_two), &
                  new_unittest("highest eigenvalue: chain, closed form and bounds", test_highest_chain), &
                  new_unittest("highest eigenvalue: Lanczos equals dsygv", test_highest_against_dense), &
                  new_unittest("general modes: constrained chain closed form", test_general_chain), &
                  new_unittest("general highest eigenvalue: chain closed form", test_general_highest) &
                  ]
   end subroutine collect_modes

   !> A chain of n = 300 masses m given as K_x entries alone (k on the diagonal's neighbours'
   !> sums, -k off it: DOF 1 to the table), held at DOF n by two linked devices of directions
   !> 2 e_n and -e_n (one constraint, given twice: rank one) and a third, unlinked device
   !> between 10 and 20 with no stiffness: the chain fixed at both ends, n - 1 moving masses,
   !> w_j^2 = (4 k / m) sin^2(j pi / (2 n)). The five lowest to 1e-10; nfree = n - 1; the
   !> shapes M-normalized and zero at DOF n.
   subroutine test_general_chain(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 300, nev = 5
      real(dp), parameter :: m = 3.0_dp, k = 1.0e6_dp
      real(dp) :: mass(n), kv(2*n - 1), lam(nev), phi(n, nev), scale, exact
      integer :: ki(2*n - 1), kj(2*n - 1), i, j, nfree
      type(lib_error), allocatable :: err

      mass = m
      do i = 1, n
         ki(i) = i; kj(i) = i; kv(i) = merge(k, 2.0_dp*k, i == n)
      end do
      do i = 1, n - 1
         ki(n + i) = i; kj(n + i) = i + 1; kv(n + i) = -k
      end do
      call general_lowest_modes(mass, [integer ::], [integer ::], [real(dp) ::], ki, kj, kv, [1, 2, 3, 5], &
                                [n, n, 10, 20], [2.0_dp, -1.0_dp, 1.0_dp, -1.0_dp], [0.0_dp, 0.0_dp, 0.0_dp], &
                                [.true., .true., .false.], nev, lam, phi, nfree, scale, err)
      call check(error, .not. allocated(err), 'general_lowest_modes')
      if (allocated(error)) return
      call check(error, nfree, n - 1, 'one constraint given twice: n - 1 free DOFs')
      if (allocated(error)) return
      do j = 1, nev
         exact = 4.0_dp*k/m*sin(j*pi/(2.0_dp*n))**2
         call check_close(error, lam(j), exact, 1.0e-10_dp, 'w^2 of the chain fixed at both ends')
         if (allocated(error)) return
         call check_close(error, sum(mass*phi(:, j)**2), 1.0_dp, 1.0e-12_dp, 'M-normalized')
         if (allocated(error)) return
         call check(error, abs(phi(n, j)) <= 1.0e-13_dp*maxval(abs(phi(:, j))), 'held at DOF n')
         if (allocated(error)) return
      end do
   end subroutine test_general_chain

   !> The highest eigenvalue of a fixed-base chain of n masses given as K_x entries plus a
   !> device of stiffness 0 (4 k / m sin^2((2n - 1) pi / (2 (2n + 1)))): n = 40 by dsygv to
   !> 1e-12, n = 3000 by Lanczos within 1e-4 and never above it; Gershgorin's bound 4 k / m
   !> above it in both.
   subroutine test_general_highest(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), parameter :: m = 2.0_dp, k = 5.0e5_dp
      real(dp), allocatable :: mass(:), kv(:)
      integer, allocatable :: ki(:), kj(:)
      real(dp) :: lam, bound, exact
      integer :: n, i, c
      type(lib_error), allocatable :: err

      do c = 1, 2
         n = merge(40, 3000, c == 1)
         mass = [(m, i=1, n)]
         ki = [(i, i=1, n), (i, i=1, n - 1)]
         kj = [(i, i=1, n), (i + 1, i=1, n - 1)]
         kv = [(merge(k, 2.0_dp*k, i == n), i=1, n), (-k, i=1, n - 1)]
         call general_highest_eigenvalue(mass, [integer ::], [integer ::], [real(dp) ::], ki, kj, kv, [1, 3], &
                                         [1, 2], [1.0_dp, -1.0_dp], [0.0_dp], lam, bound, err)
         call check(error, .not. allocated(err), 'general_highest_eigenvalue')
         if (allocated(error)) return
         exact = 4.0_dp*k/m*sin((2*n - 1)*pi/(2.0_dp*(2*n + 1)))**2
         call check_close(error, lam, exact, merge(1.0e-12_dp, 1.0e-4_dp, n == 40), 'largest eigenvalue')
         if (allocated(error)) return
         call check(error, lam <= exact*(1.0_dp + 1.0e-12_dp), 'a lower bound')
         if (allocated(error)) return
         call check(error, bound >= exact .and. bound <= 4.0_dp*k/m*(1.0_dp + 1.0e-15_dp), 'Gershgorin: 4 k / m')
         if (allocated(error)) return
      end do
   end subroutine test_general_highest

   !> A fixed-base chain of n equal masses m and springs k: w_j^2 = (4 k / m) sin^2((2j - 1) pi
   !> / (2 (2 n + 1))). n = 2000 by subspace iteration, the five lowest to 1e-12.
   subroutine test_chain_closed_form(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 2000, nev = 5
      real(dp), parameter :: m = 3.0_dp, k = 1.0e6_dp
      real(dp) :: mass(n), ek(n), lam(nev), phi(n, nev), scale, exact
      integer :: ei(n), ej(n), i, j
      type(lib_error), allocatable :: err

      mass = m
      do i = 1, n
         ei(i) = i; ej(i) = i - 1; ek(i) = k
      end do
      call lowest_modes(mass, ei, ej, ek, nev, lam, phi, scale, err, path=modes_iterative)
      call check(error, .not. allocated(err), 'lowest_modes failed: '//text(err))
      if (allocated(error)) return
      do j = 1, nev
         exact = 4.0_dp*k/m*sin((2*j - 1)*pi/(2.0_dp*(2*n + 1)))**2
         call check_close(error, lam(j), exact, 1.0e-12_dp, 'chain eigenvalue')
         if (allocated(error)) return
         call check_close(error, sum(mass*phi(:, j)**2), 1.0_dp, 1.0e-12_dp, 'M-normalized')
         if (allocated(error)) return
      end do
      call check(error, scale >= 4.0_dp*k/m, 'the scale bounds the spectrum')
   end subroutine test_chain_closed_form

   !> Randomly numbered chains of random masses and springs, n = 60: the iterative path gives
   !> dsygv's lowest eigenvalues to dsygv's own accuracy (64 eps of the largest eigenvalue)
   !> and its mode shapes (up to sign) to 1e-8.
   subroutine test_against_dense(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 60, nev = 4
      real(dp) :: mass(n), ek(n), l1(nev), l2(nev), p1(n, nev), p2(n, nev), s1, s2, r
      integer :: ei(n), ej(n), j, trial
      type(lib_error), allocatable :: err

      do trial = 1, 3
         call random_chain(17*trial, trial, mass, ei, ej, ek)
         call lowest_modes(mass, ei, ej, ek, nev, l1, p1, s1, err, path=modes_dense)
         call check(error, .not. allocated(err), 'dense modes failed: '//text(err))
         if (allocated(error)) return
         call lowest_modes(mass, ei, ej, ek, nev, l2, p2, s2, err, path=modes_iterative)
         call check(error, .not. allocated(err), 'iterative modes failed: '//text(err))
         if (allocated(error)) return
         do j = 1, nev
            ! dsygv's error is backward, relative to the spectrum's largest eigenvalue s1
            call check_close(error, l2(j), l1(j), 64.0_dp*epsilon(1.0_dp)*s1, 'eigenvalue against dsygv', &
                             absolute=.true.)
            if (allocated(error)) return
            r = sign(1.0_dp, sum(p1(:, j)*p2(:, j)))
            call check_close(error, maxval(abs(p2(:, j) - r*p1(:, j))), 0.0_dp, 1.0e-8_dp*maxval(abs(p1(:, j))), &
                             'mode shape against dsygv', absolute=.true.)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_against_dense

   !> A plane frame of 4 columns and 50 floors (band 4 after RCM): the three lowest modes
   !> satisfy K phi = lambda M phi to 1e-9 of lambda M phi and are K- and M-orthogonal.
   subroutine test_frame(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: nx = 4, ny = 50, n = nx*ny, nev = 3
      real(dp), allocatable :: ek(:), kphi(:)
      integer, allocatable :: ei(:), ej(:)
      real(dp) :: mass(n), lam(nev), phi(n, nev), scale, res, kab
      integer :: c, f, e, a, b, i
      type(lib_error), allocatable :: err

      allocate (ei(0), ej(0), ek(0))
      do f = 1, ny
         do c = 1, nx
            mass(node(c, f)) = 2.0_dp + 0.1_dp*c
            ei = [ei, node(c, f)]; ej = [ej, merge(node(c, f - 1), 0, f > 1)]; ek = [ek, 5.0e3_dp]
            if (c < nx) then
               ei = [ei, node(c, f)]; ej = [ej, node(c + 1, f)]; ek = [ek, 2.0e3_dp]
            end if
         end do
      end do
      call lowest_modes(mass, ei, ej, ek, nev, lam, phi, scale, err, path=modes_iterative)
      call check(error, .not. allocated(err), 'lowest_modes failed: '//text(err))
      if (allocated(error)) return
      allocate (kphi(n))
      do i = 1, nev
         kphi = 0.0_dp
         do e = 1, size(ei)
            a = ei(e); b = ej(e)
            kphi(a) = kphi(a) + ek(e)*(phi(a, i) - value(b, i))
            if (b > 0) kphi(b) = kphi(b) - ek(e)*(phi(a, i) - phi(b, i))
         end do
         res = maxval(abs(kphi - lam(i)*mass*phi(:, i)))/maxval(abs(lam(i)*mass*phi(:, i)))
         call check_close(error, res, 0.0_dp, 1.0e-9_dp, 'residual of K phi = lambda M phi', absolute=.true.)
         if (allocated(error)) return
         if (i > 1) then
            call check_close(error, sum(mass*phi(:, i)*phi(:, 1)), 0.0_dp, 1.0e-10_dp, 'M-orthogonal', &
                             absolute=.true.)
            if (allocated(error)) return
            kab = 0.0_dp
            do e = 1, size(ei)
               a = ei(e); b = ej(e)
               kab = kab + ek(e)*(phi(a, i) - value(b, i))*(phi(a, 1) - value(b, 1))
            end do
            call check_close(error, kab/lam(i), 0.0_dp, 1.0e-10_dp, 'K-orthogonal', absolute=.true.)
            if (allocated(error)) return
         end if
      end do
   contains
      pure integer function node(c, f)
         integer, intent(in) :: c, f
         node = (f - 1)*nx + c
      end function node
      pure real(dp) function value(b, i)
         integer, intent(in) :: b, i
         value = 0.0_dp
         if (b > 0) value = phi(b, i)
      end function value
   end subroutine test_frame

   !> Two masses, each on a spring to the table and coupled by a third: the larger root of
   !> m1 m2 l^2 - (m1 (k2 + kc) + m2 (k1 + kc)) l + k1 k2 + kc (k1 + k2) = 0, to 1e-12 (the
   !> dense path), and Gershgorin's bound above it.
   subroutine test_highest_two(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), parameter :: m1 = 6.301_dp, m2 = 2.530_dp, k1 = 1084.0_dp, k2 = 2895.0_dp, kc = 1.36e6_dp
      real(dp) :: lam, bound, b, c, exact
      type(lib_error), allocatable :: err

      call highest_eigenvalue([m1, m2], [1, 2, 1], [0, 0, 2], [k1, k2, kc], lam, bound, err)
      call check(error, .not. allocated(err), 'highest_eigenvalue failed: '//text(err))
      if (allocated(error)) return
      b = (m1*(k2 + kc) + m2*(k1 + kc))/(m1*m2)
      c = (k1*k2 + kc*(k1 + k2))/(m1*m2)
      exact = 0.5_dp*(b + sqrt(b*b - 4.0_dp*c))
      call check_close(error, lam, exact, 1.0e-12_dp, 'two-mass highest eigenvalue')
      if (allocated(error)) return
      call check(error, bound >= exact*(1.0_dp - 1.0e-14_dp), 'Gershgorin bounds the highest eigenvalue')
   end subroutine test_highest_two

   !> A fixed-base chain of n equal masses (the Lanczos path, n = 3000): the largest
   !> eigenvalue (4 k / m) sin^2((2n - 1) pi / (2 (2n + 1))); the Ritz value is below it (to
   !> rounding) and within 1e-4 of it (4.6e-5 after 120 steps: the top of a chain's spectrum
   !> is crowded, neighbours 2e-6 of it apart, and the Ritz value converges to the crowd, not
   !> to one eigenvalue; ample to compare a step with the shortest period), and Gershgorin's
   !> bound 4 k / m is above it.
   subroutine test_highest_chain(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 3000
      real(dp), parameter :: m = 3.0_dp, k = 1.0e6_dp
      real(dp), allocatable :: mass(:), ek(:)
      integer, allocatable :: ei(:), ej(:)
      real(dp) :: lam, bound, exact
      integer :: i
      type(lib_error), allocatable :: err

      allocate (mass(n), ek(n), ei(n), ej(n))
      mass = m
      do i = 1, n
         ei(i) = i; ej(i) = i - 1; ek(i) = k
      end do
      call highest_eigenvalue(mass, ei, ej, ek, lam, bound, err)
      call check(error, .not. allocated(err), 'highest_eigenvalue failed: '//text(err))
      if (allocated(error)) return
      exact = 4.0_dp*k/m*sin((2*n - 1)*pi/(2.0_dp*(2*n + 1)))**2
      call check(error, lam <= exact*(1.0_dp + 1.0e-13_dp), 'the Ritz value is a lower bound')
      if (allocated(error)) return
      call check_close(error, lam, exact, 1.0e-4_dp, 'chain highest eigenvalue')
      if (allocated(error)) return
      call check_close(error, bound, 4.0_dp*k/m, 1.0e-14_dp, "Gershgorin's bound of a uniform chain")
   end subroutine test_highest_chain

   !> Randomly numbered chains of random masses and springs, n = 150 (the Lanczos path): the
   !> highest eigenvalue equals dsygv's to 1e-8 (a spectrum without a crowd at its top: the
   !> masses and springs vary by a factor 2).
   subroutine test_highest_against_dense(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 150
      real(dp) :: mass(n), ek(n), l1(1), p1(n, 1), s1, lam, bound
      integer :: ei(n), ej(n), trial
      type(lib_error), allocatable :: err

      do trial = 1, 3
         call random_chain(13*trial, trial, mass, ei, ej, ek)
         ! dsygv's largest eigenvalue: the scale lowest_modes reports on its dense path
         call lowest_modes(mass, ei, ej, ek, 1, l1, p1, s1, err, path=modes_dense)
         call check(error, .not. allocated(err), 'dense modes failed: '//text(err))
         if (allocated(error)) return
         call highest_eigenvalue(mass, ei, ej, ek, lam, bound, err)
         call check(error, .not. allocated(err), 'highest_eigenvalue failed: '//text(err))
         if (allocated(error)) return
         call check_close(error, lam, s1, 1.0e-8_dp, 'highest eigenvalue against dsygv')
         if (allocated(error)) return
         call check(error, bound >= s1*(1.0_dp - 1.0e-14_dp), 'Gershgorin bounds the highest eigenvalue')
         if (allocated(error)) return
      end do
   end subroutine test_highest_against_dense

   !> Two masses joined by a spring, nothing to the table: a rigid-body mode (lambda below
   !> 1e-12 of the spectrum's scale) and the spring's mode, 2 k / m for equal masses; both paths.
   subroutine test_rigid(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: lam(2), phi(2, 2), scale
      integer :: path
      type(lib_error), allocatable :: err

      do path = modes_dense, modes_iterative
         call lowest_modes([2.0_dp, 2.0_dp], [1], [2], [800.0_dp], 2, lam, phi, scale, err, path=path)
         call check(error, .not. allocated(err), 'lowest_modes failed: '//text(err))
         if (allocated(error)) return
         call check(error, abs(lam(1)) <= 1.0e-12_dp*scale, 'rigid-body mode not recognised')
         if (allocated(error)) return
         call check_close(error, lam(2), 800.0_dp, 1.0e-12_dp, 'the spring mode 2 k / m')
         if (allocated(error)) return
      end do
   end subroutine test_rigid

   ! ---------------------------------------------------------------- helpers
   function text(err) result(msg)
      type(lib_error), allocatable, intent(in) :: err
      character(len=300) :: msg
      msg = ''
      if (allocated(err)) msg = err%message
   end function text

   !> A randomly numbered chain (permutation seed s) of masses 1..2 kg and springs 1..2 kN/m
   !> (hash seed trial), n = size(mass) nodes, fixed at one end.
   pure subroutine random_chain(s, trial, mass, ei, ej, ek)
      integer, intent(in) :: s, trial
      real(dp), intent(out) :: mass(:), ek(:)
      integer, intent(out) :: ei(:), ej(:)
      integer :: q(size(mass)), i, n

      n = size(mass)
      call permutation(n, s, q)
      do i = 1, n
         mass(q(i)) = 1.0_dp + hashed(i, trial)
         ei(i) = q(i)
         ej(i) = 0
         if (i > 1) ej(i) = q(i - 1)
         ek(i) = 1.0e3_dp*(1.0_dp + hashed(i + n, trial))
      end do
   end subroutine random_chain

   pure subroutine permutation(n, s, q)
      integer, intent(in) :: n, s
      integer, intent(out) :: q(n)
      integer :: i, j, t
      q = [(i, i=1, n)]
      do i = n, 2, -1
         j = 1 + mod(i*s + 7*i*i, i)
         t = q(i); q(i) = q(j); q(j) = t
      end do
   end subroutine permutation

   pure real(dp) function hashed(i, s)
      integer, intent(in) :: i, s
      hashed = modulo(sin(real(i*37 + s*101, dp))*43758.5453_dp, 1.0_dp)
   end function hashed

end module test_fd_modes
