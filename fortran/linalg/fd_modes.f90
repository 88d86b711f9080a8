!> The lowest natural modes of a lumped-mass structure,
!>
!>   K phi = lambda M phi,   lambda = w^2,   M = diag(m),
!>
!> K assembled from two-node elements (springs) between nodes 0..n, node 0 fixed (the
!> table). One routine for every modal question of the code (the stuck system's first
!> period, the periods and mode shapes of the stuck and free systems in the summary): the
!> caller reduces its system (rigid links grouped) to masses and element lists.
!>
!> Small systems (n <= modes_dense_max) are solved dense by LAPACK's dsygv: every mode,
!> O(n^3) time, O(n^2) memory. Larger ones by subspace iteration (Bathe, *Finite Element
!> Procedures*, 11.6) on q = min(n, max(2 nev, nev + 8)) vectors with the banded Cholesky
!> factor of K + delta M (fd_banded: reverse Cuthill-McKee ordering, LAPACK band Cholesky):
!> memory O(n (bandwidth + q)), time O(n bandwidth^2) for the factor and O(n q (bandwidth + q))
!> per iteration; it converges like (lambda_i / lambda_(q+1))^k. The tiny shift delta (1e-10
!> of the Gershgorin bound of the spectrum) keeps a structure with a rigid-body mode
!> factorable, so that the caller can recognise that mode (lambda ~ 0) and say so.
!> The Ritz projection takes x' K y from the elements, sum_e k_e (x_i - x_j)(y_i - y_j), which
!> has no cancellation: the eigenvalues come out to a few ulps of the projected problem.
module fd_modes
   use fd_kinds, only: dp
   use fd_lapack, only: dsterf
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real, stat_no_memory
   use fd_linalg, only: generalized_eigen
   use fd_banded, only: spd_system, spd_setup, spd_factor, spd_solve
   implicit none
   private

   public :: lowest_modes, modes_auto, modes_dense, modes_iterative, modes_dense_max
   public :: highest_eigenvalue

   integer, parameter :: modes_auto = 0        !! dense up to modes_dense_max DOFs, else iterative
   integer, parameter :: modes_dense = 1       !! LAPACK dsygv on the dense matrices
   integer, parameter :: modes_iterative = 2   !! subspace iteration with the banded factor

   !> Largest n solved dense by modes_auto (dsygv at n = 64: about 1 ms).
   integer, parameter :: modes_dense_max = 64
   !> Relative change of a wanted eigenvalue below which it has converged.
   real(dp), parameter :: lambda_tol = 1.0e-13_dp
   !> Change of a wanted (M-normalized) mode shape below which it has converged.
   real(dp), parameter :: vector_tol = 1.0e-9_dp
   !> Eigenvalues closer than this (relative) are a multiple one: their vectors are not unique.
   real(dp), parameter :: cluster_tol = 1.0e-6_dp
   integer, parameter :: max_iterations = 500
   !> Lanczos steps of highest_eigenvalue at most, and the relative change of its largest
   !> Ritz value below which it stops.
   integer, parameter :: lanczos_max_steps = 120
   real(dp), parameter :: lanczos_tol = 1.0e-10_dp

contains

   !> The nev lowest eigenvalues lambda (ascending) and M-normalized mode shapes of
   !> K phi = lambda M phi, and the scale of the spectrum (the largest eigenvalue when solved
   !> dense, else its Gershgorin bound), against which a caller judges lambda ~ 0.
   subroutine lowest_modes(mass, ei, ej, ek, nev, lambda, phi, scale, error, path)
      real(dp), intent(in) :: mass(:)             !! masses m_i > 0 [kg], n = size(mass)
      integer, intent(in) :: ei(:)                !! first node of each element (0..n)
      integer, intent(in) :: ej(:)                !! second node of each element (0..n, 0 = fixed)
      real(dp), intent(in) :: ek(:)               !! element stiffness [N/m], >= 0
      integer, intent(in) :: nev                  !! modes wanted, 1..n
      real(dp), intent(out) :: lambda(:)          !! eigenvalues w^2 [1/s^2], size nev
      real(dp), intent(out) :: phi(:, :)          !! mode shapes, n x nev, phi' M phi = I
      real(dp), intent(out) :: scale              !! largest eigenvalue, or an upper bound of it
      type(error_type), allocatable, intent(out) :: error !! bad input, no convergence
      integer, intent(in), optional :: path       !! modes_auto (default), modes_dense, modes_iterative
      integer :: n, mode

      n = size(mass)
      lambda = 0.0_dp
      phi = 0.0_dp
      scale = 0.0_dp
      if (nev < 1 .or. nev > n) then
         call fatal_error(error, "lowest_modes: "//trim(fmt_int(nev))//" modes asked of "//trim(fmt_int(n))//" DOFs")
         return
      end if
      if (size(lambda) < nev .or. size(phi, 1) /= n .or. size(phi, 2) < nev) then
         call fatal_error(error, "lowest_modes: the result arrays are too small")
         return
      end if
      mode = modes_auto
      if (present(path)) mode = path
      if (mode == modes_auto) then
         mode = modes_iterative
         if (n <= modes_dense_max) mode = modes_dense
      end if
      if (mode == modes_dense) then
         call dense_modes(mass, ei, ej, ek, nev, lambda, phi, scale, error)
      else
         call subspace_modes(mass, ei, ej, ek, nev, lambda, phi, scale, error)
      end if
   end subroutine lowest_modes

   !> Every mode by LAPACK's dsygv on the assembled matrices; the first nev kept.
   subroutine dense_modes(mass, ei, ej, ek, nev, lambda, phi, scale, error)
      real(dp), intent(in) :: mass(:), ek(:)
      integer, intent(in) :: ei(:), ej(:), nev
      real(dp), intent(out) :: lambda(:), phi(:, :), scale
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: k(:, :), m(:, :), lam(:), z(:, :)
      integer :: n, e, i, j

      n = size(mass)
      allocate (k(n, n), m(n, n), lam(n), z(n, n))
      k = 0.0_dp
      m = 0.0_dp
      do e = 1, size(ei)
         i = ei(e); j = ej(e)
         if (i > 0) k(i, i) = k(i, i) + ek(e)
         if (j > 0) k(j, j) = k(j, j) + ek(e)
         if (i > 0 .and. j > 0) then
            k(i, j) = k(i, j) - ek(e)
            k(j, i) = k(j, i) - ek(e)
         end if
      end do
      do i = 1, n
         m(i, i) = mass(i)
      end do
      call generalized_eigen(k, m, lam, z, error)
      if (allocated(error)) return
      lambda(1:nev) = lam(1:nev)
      phi(:, 1:nev) = z(:, 1:nev)
      scale = maxval(abs(lam))
   end subroutine dense_modes

   !> Subspace iteration: X <- (K + delta M)^-1 M X, Rayleigh-Ritz on K and M, until the
   !> wanted eigenvalues and (where they are simple) their mode shapes stop changing.
   subroutine subspace_modes(mass, ei, ej, ek, nev, lambda, phi, scale, error)
      real(dp), intent(in) :: mass(:), ek(:)
      integer, intent(in) :: ei(:), ej(:), nev
      real(dp), intent(out) :: lambda(:), phi(:, :), scale
      type(error_type), allocatable, intent(out) :: error
      type(spd_system) :: sys
      real(dp), allocatable :: x(:, :), y(:, :), kr(:, :), mr(:, :), lam(:), lam_old(:), q(:, :), row(:)
      real(dp) :: delta, change, norm
      integer :: n, nq, it, i, j, e, a, b, pass, stat
      integer :: none(0)
      real(dp) :: no_coef(0)
      real(dp) :: nokd(0)
      logical :: done

      n = size(mass)
      nq = min(n, max(2*nev, nev + 8))
      ! Gershgorin bound of the eigenvalues of M^-1 K
      allocate (row(n))
      row = 0.0_dp
      do e = 1, size(ei)
         a = ei(e); b = ej(e)
         if (a > 0) row(a) = row(a) + merge(2.0_dp, 1.0_dp, b > 0)*ek(e)
         if (b > 0) row(b) = row(b) + merge(2.0_dp, 1.0_dp, a > 0)*ek(e)
      end do
      scale = maxval(row/mass)
      if (.not. (scale > 0.0_dp)) then
         call fatal_error(error, "lowest_modes: the structure has no stiffness")
         return
      end if
      delta = 1.0e-10_dp*scale
      call spd_setup(sys, mass, ei, ej, ek, [1], none, no_coef, error)
      if (allocated(error)) return
      call spd_factor(sys, delta, 0.0_dp, nokd, error)
      if (allocated(error)) return

      allocate (x(n, nq), y(n, nq), kr(nq, nq), mr(nq, nq), lam(nq), lam_old(nq), q(nq, nq), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the subspace iteration of the modes of "// &
                          trim(fmt_int(n))//" DOFs ("//trim(fmt_int(nq))//" vectors)", stat_no_memory)
         return
      end if
      ! start: the mass vector (it excites every DOF), then reproducible pseudo-random vectors
      x(:, 1) = mass
      do j = 2, nq
         do i = 1, n
            x(i, j) = start_value(i, j)
         end do
      end do
      lam_old = huge(1.0_dp)
      do it = 1, max_iterations
         do j = 1, nq
            y(:, j) = mass*x(:, j)
            call spd_solve(sys, y(:, j), error)
            if (allocated(error)) return
         end do
         ! M-orthonormal columns (modified Gram-Schmidt, twice): the operator scales them by up
         ! to lambda_q / lambda_1 (1e10 and more with a rigid-body mode), which would leave
         ! Y' M Y numerically singular; a column that collapses is replaced by a fresh one
         do j = 1, nq
            do pass = 1, 2
               do i = 1, j - 1
                  y(:, j) = y(:, j) - sum(mass*y(:, i)*y(:, j))*y(:, i)
               end do
            end do
            norm = sqrt(sum(mass*y(:, j)**2))
            if (.not. (norm > 1.0e-12_dp*maxval(abs(y(:, j))) .and. norm > 0.0_dp)) then
               do i = 1, n
                  y(i, j) = start_value(i, j + nq*it)
               end do
               do i = 1, j - 1
                  y(:, j) = y(:, j) - sum(mass*y(:, i)*y(:, j))*y(:, i)
               end do
               norm = sqrt(sum(mass*y(:, j)**2))
            end if
            y(:, j) = y(:, j)/norm
         end do
         ! Ritz projection: kr = Y' K Y from the elements, mr = Y' M Y
         kr = 0.0_dp
         do e = 1, size(ei)
            a = ei(e); b = ej(e)
            do j = 1, nq
               row(j) = relative(y(:, j), a, b)
            end do
            do j = 1, nq
               kr(1:j, j) = kr(1:j, j) + ek(e)*row(1:j)*row(j)
            end do
         end do
         do j = 1, nq
            do i = 1, j
               mr(i, j) = sum(mass*y(:, i)*y(:, j))
               kr(j, i) = kr(i, j)
               mr(j, i) = mr(i, j)
            end do
         end do
         call generalized_eigen(kr, mr, lam, q, error)
         if (allocated(error)) return
         x = matmul(y, q)
         ! converged: every wanted eigenvalue, and every wanted simple mode's shape
         done = it > 1
         do i = 1, nev
            ! relative to the eigenvalue, or to the shift for one at round-off (a rigid-body mode)
            if (abs(lam(i) - lam_old(i)) > lambda_tol*max(abs(lam(i)), delta)) done = .false.
         end do
         if (done) then
            do i = 1, nev
               if (i > 1) then
                  if (abs(lam(i) - lam(i - 1)) <= cluster_tol*abs(lam(i))) cycle
               end if
               if (i < nq) then
                  if (abs(lam(i + 1) - lam(i)) <= cluster_tol*abs(lam(i))) cycle
               end if
               change = sign(1.0_dp, sum(mass*x(:, i)*phi(:, i)))
               change = sqrt(sum(mass*(x(:, i) - change*phi(:, i))**2))
               if (change > vector_tol) done = .false.
            end do
         end if
         lam_old = lam
         phi(:, 1:nev) = x(:, 1:nev)
         if (done) exit
      end do
      if (.not. done) then
         call fatal_error(error, "lowest_modes: the subspace iteration did not converge in "// &
                          trim(fmt_int(max_iterations))//" iterations (lambda_1 = "//trim(fmt_real(lam(1)))//")")
         return
      end if
      lambda(1:nev) = lam(1:nev)
      ! a reproducible sign: the largest component of each mode positive
      do i = 1, nev
         j = maxloc(abs(phi(:, i)), 1)
         if (phi(j, i) < 0.0_dp) phi(:, i) = -phi(:, i)
      end do
   contains
      pure real(dp) function relative(v, a, b)
         real(dp), intent(in) :: v(:)
         integer, intent(in) :: a, b
         relative = 0.0_dp
         if (a > 0) relative = v(a)
         if (b > 0) relative = relative - v(b)
      end function relative
   end subroutine subspace_modes

   !> The largest eigenvalue of K phi = lambda M phi (the square of the highest natural
   !> circular frequency), from below and from above:
   !>
   !> - lambda: the largest Ritz value of a Lanczos run on M^-1/2 K M^-1/2 (matrix free, from
   !>   the elements: O(elements) a step, three vectors of n; no reorthogonalization, which
   !>   does not move the extreme Ritz value). A Ritz value never exceeds the largest
   !>   eigenvalue (Courant-Fischer), so lambda is a lower bound, to rounding; the Lanczos
   !>   run converges to the top of the spectrum first (Kaniel-Paige), and stops when the
   !>   largest Ritz value changes by less than lanczos_tol or after lanczos_max_steps.
   !>   Exact (dsygv) for n <= modes_dense_max.
   !> - bound: Gershgorin's upper bound of the same matrix.
   !>
   !> What a caller may conclude: lambda > x proves the largest eigenvalue above x; bound <= x
   !> proves it at most x.
   subroutine highest_eigenvalue(mass, ei, ej, ek, lambda, bound, error)
      real(dp), intent(in) :: mass(:)             !! masses m_i > 0 [kg], n = size(mass)
      integer, intent(in) :: ei(:)                !! first node of each element (0..n)
      integer, intent(in) :: ej(:)                !! second node of each element (0..n, 0 = fixed)
      real(dp), intent(in) :: ek(:)               !! element stiffness [N/m], >= 0
      real(dp), intent(out) :: lambda             !! largest Ritz value [1/s^2] (a lower bound)
      real(dp), intent(out) :: bound              !! Gershgorin bound [1/s^2] (an upper bound)
      type(error_type), allocatable, intent(out) :: error !! bad input, no memory, LAPACK failure
      real(dp), allocatable :: rs(:), dm(:), q0(:), q1(:), w(:), alpha(:), beta(:), d(:), e(:), lam(:), phi(:, :)
      real(dp) :: nrm, top, prev, x
      integer :: n, ne, i, a, b, k, info, stat

      n = size(mass)
      ne = size(ek)
      lambda = 0.0_dp
      bound = 0.0_dp
      if (size(ei) /= ne .or. size(ej) /= ne) then
         call fatal_error(error, "highest_eigenvalue: the element lists differ in length")
         return
      end if
      if (n == 0) return
      if (any(mass <= 0.0_dp)) then
         call fatal_error(error, "highest_eigenvalue: a mass is not positive")
         return
      end if
      if (any(ei < 0 .or. ei > n .or. ej < 0 .or. ej > n)) then
         call fatal_error(error, "highest_eigenvalue: an element node is outside 0.."//trim(fmt_int(n)))
         return
      end if
      ! Gershgorin on D K D, D = M^-1/2: row i holds k_e / m_i on the diagonal and
      ! k_e / sqrt(m_i m_j) off it, for each element e at i
      allocate (rs(n), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "highest_eigenvalue: not enough memory for "//trim(fmt_int(n))//" DOFs", &
                          stat_no_memory)
         return
      end if
      rs = 0.0_dp
      do i = 1, ne
         a = ei(i); b = ej(i)
         if (a == b) cycle
         if (a > 0) rs(a) = rs(a) + abs(ek(i))/mass(a)
         if (b > 0) rs(b) = rs(b) + abs(ek(i))/mass(b)
         if (a > 0 .and. b > 0) then
            x = abs(ek(i))/sqrt(mass(a)*mass(b))
            rs(a) = rs(a) + x
            rs(b) = rs(b) + x
         end if
      end do
      bound = maxval(rs)
      if (bound == 0.0_dp) return
      if (n <= modes_dense_max) then   ! dsygv: every eigenvalue, the largest exact
         allocate (lam(1), phi(n, 1), stat=stat)
         if (stat /= 0) then
            call fatal_error(error, "highest_eigenvalue: not enough memory", stat_no_memory)
            return
         end if
         call dense_modes(mass, ei, ej, ek, 1, lam, phi, lambda, error)
         return
      end if
      ! Lanczos on A = D K D from a reproducible pseudo-random start
      allocate (dm(n), q0(n), q1(n), w(n), alpha(lanczos_max_steps), beta(lanczos_max_steps), &
                d(lanczos_max_steps), e(lanczos_max_steps), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "highest_eigenvalue: not enough memory for "//trim(fmt_int(n))//" DOFs", &
                          stat_no_memory)
         return
      end if
      do i = 1, n
         dm(i) = 1.0_dp/sqrt(mass(i))   ! D, once
         q1(i) = start_value(i, 1)
      end do
      q1 = q1/norm2(q1)
      q0 = 0.0_dp
      prev = -1.0_dp
      top = 0.0_dp
      do k = 1, min(lanczos_max_steps, n)
         ! w = D K D q1 - beta_(k-1) q0 (rs, free after Gershgorin, holds D q1)
         do i = 1, n
            rs(i) = dm(i)*q1(i)
         end do
         w = 0.0_dp
         do i = 1, ne
            a = ei(i); b = ej(i)
            x = 0.0_dp
            if (a > 0) x = rs(a)
            if (b > 0) x = x - rs(b)
            x = ek(i)*x
            if (a > 0) w(a) = w(a) + x
            if (b > 0) w(b) = w(b) - x
         end do
         do i = 1, n
            w(i) = dm(i)*w(i)
         end do
         if (k > 1) w = w - beta(k - 1)*q0
         alpha(k) = dot_product(w, q1)
         w = w - alpha(k)*q1
         nrm = norm2(w)
         beta(k) = nrm
         ! the largest eigenvalue of the tridiagonal T_k (alpha, beta(1:k-1))
         d(1:k) = alpha(1:k)
         e(1:k) = beta(1:k)
         call dsterf(k, d, e, info)
         if (info /= 0) then
            call fatal_error(error, "highest_eigenvalue: dsterf failed with info = "//trim(fmt_int(info)))
            return
         end if
         top = d(k)
         if (nrm <= epsilon(1.0_dp)*bound) exit            ! an invariant subspace: T_k is exact
         if (abs(top - prev) <= lanczos_tol*abs(top)) exit
         prev = top
         q0 = q1
         q1 = w/nrm
      end do
      lambda = min(top, bound)
   end subroutine highest_eigenvalue

   !> A reproducible pseudo-random number in [-1, 1) for entry (i, j) of the start vectors
   !> (a hash of i and j: no generator state).
   pure real(dp) function start_value(i, j) result(x)
      integer, intent(in) :: i, j
      integer, parameter :: i8 = selected_int_kind(18)
      integer(i8), parameter :: m31 = 2147483647_i8
      integer(i8) :: h
      integer :: r

      h = mod(int(i, i8)*7919_i8 + int(j, i8)*104729_i8 + 12345_i8, m31)
      do r = 1, 3
         h = mod(h*48271_i8, m31)   ! Park-Miller: h < 2^31, no overflow
      end do
      x = 2.0_dp*real(h, dp)/real(m31, dp) - 1.0_dp
   end function start_value

end module fd_modes
