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
   use fd_lapack, only: dsterf, dpotrf, dpotrs
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real, stat_no_memory
   use fd_linalg, only: generalized_eigen
   use fd_banded, only: spd_system, spd_setup, spd_factor, spd_solve
   implicit none
   private

   public :: lowest_modes, modes_auto, modes_dense, modes_iterative, modes_dense_max
   public :: highest_eigenvalue, general_lowest_modes, general_highest_eigenvalue

   !> The operator of general_lowest_modes: the banded factor of A = K + sum kd b b' + delta M
   !> and the constraints' orthonormal basis W (n x r), Y = A^-1 W and the Cholesky factor
   !> of S = W' Y.
   type :: constrained_operator
      type(spd_system) :: sys
      integer :: r = 0
      real(dp) :: delta = 0.0_dp
      real(dp), allocatable :: w(:, :), y(:, :), s(:, :), t(:)
   end type constrained_operator

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
   !> Multiple of eps times the spectrum's bound below which general_lowest_modes takes a
   !> change of an eigenvalue (or, over the gap to its neighbours, of a shape) as rounding:
   !> products with a K_x of any sign carry errors of that size, which no iteration removes.
   real(dp), parameter :: rounding_floor = 64.0_dp

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
      real(dp) :: delta
      integer :: n, nq, it, j, e, a, b
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

      call subspace_start(mass, nq, x, y, kr, mr, lam, lam_old, q, error)
      if (allocated(error)) return
      do it = 1, max_iterations
         do j = 1, nq
            y(:, j) = mass*x(:, j)
            call spd_solve(sys, y(:, j), error)
            if (allocated(error)) return
         end do
         ! M-orthonormal columns: the operator scales them by up to lambda_q / lambda_1 (1e10
         ! and more with a rigid-body mode), which would leave Y' M Y numerically singular
         call m_orthonormalize(mass, y, it, 1)
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
         call ritz_vectors(mass, y, kr, mr, lam, q, x, error)
         if (allocated(error)) return
         ! converged: every wanted eigenvalue (relative to itself, or to the shift for one at
         ! round-off: a rigid-body mode), and every wanted simple mode's shape
         done = it > 1
         if (done) done = subspace_settled(mass, x, phi, lam, lam_old, nev, lambda_tol*delta, 0.0_dp)
         lam_old = lam
         phi(:, 1:nev) = x(:, 1:nev)
         if (done) exit
      end do
      call subspace_result(done, lam, nev, lambda, phi, error)
   contains
      pure real(dp) function relative(v, a, b)
         real(dp), intent(in) :: v(:)
         integer, intent(in) :: a, b
         relative = 0.0_dp
         if (a > 0) relative = v(a)
         if (b > 0) relative = relative - v(b)
      end function relative
   end subroutine subspace_modes

   !> The nev lowest modes of a general structure, without an n x n matrix:
   !>
   !>   (K + sum_d kd_d b_d b_d') phi = lambda M phi   on   b_d' phi = 0 for every linked d,
   !>
   !> K the springs and K_x (its entries on and above the diagonal), b_d device d's direction
   !> (compressed by device), M = diag(mass). Subspace iteration (Bathe, 11.6) on
   !> q = min(nfree, max(2 nev, nev + 8)) vectors with the constrained shift-invert operator
   !> X <- (A^-1 - Y S^-1 Y') M X: A = K + sum kd b b' + delta M factored in band storage
   !> after reverse Cuthill-McKee (fd_banded, delta = 1e-10 of the Gershgorin bound), W an
   !> orthonormal basis of the linked directions' span (the eigenvectors of their Gram matrix
   !> whose eigenvalue is above 1e-12 of the largest, as the dense null space takes those of
   !> B B'), Y = A^-1 W and S = W' Y (r x r): each iterate satisfies W' x = 0, so the
   !> modes are those on the constraints' null space (dimension nfree = n - r). Memory
   !> O(n (bandwidth + r + q)); time O(n bandwidth^2 + r n bandwidth) to set up and
   !> O(n q (bandwidth + q)) an iteration. Converged when every wanted eigenvalue changes by
   !> less than 1e-13 of itself, and every simple wanted shape by less than 1e-9 (M-norm),
   !> or by less than the rounding of the spectrum's scale (rounding_floor eps scale, over
   !> the gap for a shape), which products with K_x cannot go below. m = min(nev, nfree)
   !> modes are returned (none when nfree = 0), M-normalized, the largest component of each
   !> positive; scale is the Gershgorin bound of M^-1 (K + sum kd b b').
   subroutine general_lowest_modes(mass, spring_i, spring_j, spring_k, kx_i, kx_j, kx_v, dev_ptr, dev_dof, &
                                   dev_coef, kd, linked, nev, lambda, phi, nfree, scale, error)
      real(dp), intent(in) :: mass(:)             !! masses m_i > 0, n = size(mass)
      integer, intent(in) :: spring_i(:)          !! first node of each spring (0..n)
      integer, intent(in) :: spring_j(:)          !! second node of each spring (0..n, 0 = fixed)
      real(dp), intent(in) :: spring_k(:)         !! spring stiffness >= 0
      integer, intent(in) :: kx_i(:)              !! K_x: row of each entry (1..n)
      integer, intent(in) :: kx_j(:)              !! its column (kx_i <= kx_j)
      real(dp), intent(in) :: kx_v(:)             !! its value
      integer, intent(in) :: dev_ptr(:)           !! start of each device's terms (devices + 1)
      integer, intent(in) :: dev_dof(:)           !! DOF of each term
      real(dp), intent(in) :: dev_coef(:)         !! coefficient of each term
      real(dp), intent(in) :: kd(:)               !! each device's stiffness in K (>= 0; 0: none)
      logical, intent(in) :: linked(:)            !! the devices whose direction is a constraint
      integer, intent(in) :: nev                  !! modes wanted, >= 1
      real(dp), intent(out) :: lambda(:)          !! eigenvalues w^2, ascending, size >= nev
      real(dp), intent(out) :: phi(:, :)          !! mode shapes (n, >= nev), phi' M phi = I
      integer, intent(out) :: nfree               !! dimension of the constraints' null space
      real(dp), intent(out) :: scale              !! Gershgorin bound of the spectrum
      type(error_type), allocatable, intent(out) :: error !! no stiffness, no memory, no convergence
      type(constrained_operator) :: op
      integer, allocatable :: ci(:), cj(:)
      real(dp), allocatable :: cv(:), row(:)
      integer :: n, stat

      n = size(mass)
      lambda = 0.0_dp
      phi = 0.0_dp
      nfree = n
      scale = 0.0_dp
      if (nev < 1 .or. size(lambda) < nev .or. size(phi, 1) /= n .or. size(phi, 2) < nev) then
         call fatal_error(error, "general_lowest_modes: "//trim(fmt_int(nev))//" modes asked, or result arrays "// &
                          "too small for them")
         return
      end if
      call stiffness_entries(n, spring_i, spring_j, spring_k, kx_i, kx_j, kx_v, dev_ptr, dev_dof, dev_coef, kd, &
                             ci, cj, cv, stat)
      if (stat == 0) allocate (row(n), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the modes of "//trim(fmt_int(n))//" DOFs", stat_no_memory)
         return
      end if
      call entry_rows(ci, cj, cv, row)
      scale = maxval(row/mass)
      if (.not. (scale > 0.0_dp)) then
         call fatal_error(error, "lowest_modes: the structure has no stiffness")
         return
      end if
      call operator_setup(op, mass, spring_i, spring_j, spring_k, kx_i, kx_j, kx_v, dev_ptr, dev_dof, dev_coef, &
                          kd, linked, 1.0e-10_dp*scale, error)
      if (allocated(error)) return
      nfree = n - op%r
      if (nfree == 0) return
      call constrained_subspace(op, mass, ci, cj, cv, min(nev, nfree), nfree, scale, lambda, phi, error)
   end subroutine general_lowest_modes

   !> K + sum kd b b' as a list of entries on and above the diagonal (ci <= cj): the springs'
   !> (k on both diagonals, -k off them), K_x's, and kd c_p c_q for each pair of a device's terms.
   subroutine stiffness_entries(n, spring_i, spring_j, spring_k, kx_i, kx_j, kx_v, dev_ptr, dev_dof, dev_coef, &
                                kd, ci, cj, cv, stat)
      integer, intent(in) :: n, spring_i(:), spring_j(:), kx_i(:), kx_j(:), dev_ptr(:), dev_dof(:)
      real(dp), intent(in) :: spring_k(:), kx_v(:), dev_coef(:), kd(:)
      integer, allocatable, intent(out) :: ci(:), cj(:)
      real(dp), allocatable, intent(out) :: cv(:)
      integer, intent(out) :: stat
      integer :: ne, e, d, p, q, a, b

      ne = 3*size(spring_k) + size(kx_v)
      do d = 1, size(dev_ptr) - 1
         if (kd(d) /= 0.0_dp) ne = ne + (dev_ptr(d + 1) - dev_ptr(d))*(dev_ptr(d + 1) - dev_ptr(d) + 1)/2
      end do
      allocate (ci(ne), cj(ne), cv(ne), stat=stat)
      if (stat /= 0 .or. n < 0) return
      ne = 0
      do e = 1, size(spring_k)
         a = spring_i(e); b = spring_j(e)
         if (a > 0) call put(a, a, spring_k(e))
         if (b > 0) call put(b, b, spring_k(e))
         if (a > 0 .and. b > 0 .and. a /= b) call put(min(a, b), max(a, b), -spring_k(e))
      end do
      do e = 1, size(kx_v)
         call put(kx_i(e), kx_j(e), kx_v(e))
      end do
      do d = 1, size(dev_ptr) - 1
         if (kd(d) == 0.0_dp) cycle
         do p = dev_ptr(d), dev_ptr(d + 1) - 1
            do q = p, dev_ptr(d + 1) - 1
               a = dev_dof(p); b = dev_dof(q)
               if (a == b .and. p /= q) then
                  call put(a, a, 2.0_dp*kd(d)*dev_coef(p)*dev_coef(q))
               else
                  call put(min(a, b), max(a, b), kd(d)*dev_coef(p)*dev_coef(q))
               end if
            end do
         end do
      end do
      ci = ci(1:ne); cj = cj(1:ne); cv = cv(1:ne)
   contains
      subroutine put(i, j, v)
         integer, intent(in) :: i, j
         real(dp), intent(in) :: v
         ne = ne + 1
         ci(ne) = i; cj(ne) = j; cv(ne) = v
      end subroutine put
   end subroutine stiffness_entries

   !> y = A x for the symmetric A given by its entries on and above the diagonal.
   pure subroutine entry_product(ci, cj, cv, x, y)
      integer, intent(in) :: ci(:), cj(:)
      real(dp), intent(in) :: cv(:), x(:)
      real(dp), intent(out) :: y(:)
      integer :: e

      y = 0.0_dp
      do e = 1, size(cv)
         y(ci(e)) = y(ci(e)) + cv(e)*x(cj(e))
         if (ci(e) /= cj(e)) y(cj(e)) = y(cj(e)) + cv(e)*x(ci(e))
      end do
   end subroutine entry_product

   !> The rows' sums of |A| (Gershgorin) of the symmetric A given by its upper entries.
   pure subroutine entry_rows(ci, cj, cv, row)
      integer, intent(in) :: ci(:), cj(:)
      real(dp), intent(in) :: cv(:)
      real(dp), intent(out) :: row(:)
      integer :: e

      row = 0.0_dp
      do e = 1, size(cv)
         row(ci(e)) = row(ci(e)) + abs(cv(e))
         if (ci(e) /= cj(e)) row(cj(e)) = row(cj(e)) + abs(cv(e))
      end do
   end subroutine entry_rows

   !> The constrained operator: A factored (fd_banded), the linked directions' Gram matrix
   !> G = B' B and its eigenvectors V, W = B V_r diag(e_r)^-1/2 for the r eigenvalues e above
   !> 1e-12 of the largest (orthonormal), Y = A^-1 W, S = W' Y and its Cholesky factor.
   subroutine operator_setup(op, mass, spring_i, spring_j, spring_k, kx_i, kx_j, kx_v, dev_ptr, dev_dof, &
                             dev_coef, kd, linked, delta, error)
      type(constrained_operator), intent(out) :: op
      real(dp), intent(in) :: mass(:), spring_k(:), kx_v(:), dev_coef(:), kd(:), delta
      integer, intent(in) :: spring_i(:), spring_j(:), kx_i(:), kx_j(:), dev_ptr(:), dev_dof(:)
      logical, intent(in) :: linked(:)
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: g(:, :), eye(:, :), ev(:), vec(:, :), v(:)
      integer, allocatable :: lk(:)
      integer :: n, nc, a, b, k, p, col, info, stat

      n = size(mass)
      op%delta = delta
      call spd_setup(op%sys, mass, spring_i, spring_j, spring_k, dev_ptr, dev_dof, dev_coef, error, &
                     kx_i=kx_i, kx_j=kx_j, kx_v=kx_v)
      if (allocated(error)) return
      call spd_factor(op%sys, delta, 0.0_dp, kd, error)
      if (allocated(error)) return
      lk = pack([(a, a=1, size(linked))], linked)
      nc = size(lk)
      op%r = 0
      allocate (op%w(n, 0), op%y(n, 0), op%s(0, 0), op%t(0))
      if (nc == 0) return
      allocate (g(nc, nc), eye(nc, nc), ev(nc), vec(nc, nc), v(n), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the constraints of "//trim(fmt_int(nc))//" devices", &
                          stat_no_memory)
         return
      end if
      ! G = B' B by the devices' terms: b_a scattered into v, dotted with each b_b
      v = 0.0_dp
      eye = 0.0_dp
      do a = 1, nc
         eye(a, a) = 1.0_dp
         do p = dev_ptr(lk(a)), dev_ptr(lk(a) + 1) - 1
            v(dev_dof(p)) = v(dev_dof(p)) + dev_coef(p)
         end do
         do b = a, nc
            g(a, b) = 0.0_dp
            do p = dev_ptr(lk(b)), dev_ptr(lk(b) + 1) - 1
               g(a, b) = g(a, b) + v(dev_dof(p))*dev_coef(p)
            end do
            g(b, a) = g(a, b)
         end do
         v(dev_dof(dev_ptr(lk(a)):dev_ptr(lk(a) + 1) - 1)) = 0.0_dp
      end do
      call generalized_eigen(g, eye, ev, vec, error)
      if (allocated(error)) return
      op%r = count(ev > 1.0e-12_dp*maxval(abs(ev)))
      deallocate (op%w, op%y, op%s, op%t)
      allocate (op%w(n, op%r), op%y(n, op%r), op%s(op%r, op%r), op%t(op%r), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the constraints of "//trim(fmt_int(nc))//" devices on "// &
                          trim(fmt_int(n))//" DOFs", stat_no_memory)
         return
      end if
      op%w = 0.0_dp
      do k = 1, op%r
         col = nc - op%r + k
         do a = 1, nc
            do p = dev_ptr(lk(a)), dev_ptr(lk(a) + 1) - 1
               op%w(dev_dof(p), k) = op%w(dev_dof(p), k) + vec(a, col)*dev_coef(p)/sqrt(ev(col))
            end do
         end do
         op%y(:, k) = op%w(:, k)
         call spd_solve(op%sys, op%y(:, k), error)
         if (allocated(error)) return
      end do
      op%s = matmul(transpose(op%w), op%y)
      op%s = 0.5_dp*(op%s + transpose(op%s))
      if (op%r > 0) then
         call dpotrf('U', op%r, op%s, op%r, info)
         if (info /= 0) then
            call fatal_error(error, "lowest_modes: the constraints' Schur complement is not positive definite "// &
                             "(info = "//trim(fmt_int(info))//")")
            return
         end if
      end if
   end subroutine operator_setup

   !> x <- (A^-1 - Y S^-1 Y') x: the solution of A x' = x + W t with W' x' = 0.
   subroutine operator_apply(op, x, error)
      type(constrained_operator), intent(inout) :: op
      real(dp), intent(inout), contiguous :: x(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: info

      call spd_solve(op%sys, x, error)
      if (allocated(error) .or. op%r == 0) return
      op%t = matmul(x, op%w)
      call dpotrs('U', op%r, 1, op%s, op%r, op%t, op%r, info)
      x = x - matmul(op%y, op%t)
   end subroutine operator_apply

   !> x <- x - W W' x: x's part in the constraints' null space.
   subroutine operator_project(op, x)
      type(constrained_operator), intent(inout) :: op
      real(dp), intent(inout) :: x(:)

      if (op%r == 0) return
      op%t = matmul(x, op%w)
      x = x - matmul(op%w, op%t)
   end subroutine operator_project

   !> The subspace iteration of general_lowest_modes on the operator op; m modes wanted.
   subroutine constrained_subspace(op, mass, ci, cj, cv, m, nfree, scale, lambda, phi, error)
      type(constrained_operator), intent(inout) :: op
      real(dp), intent(in) :: mass(:), cv(:), scale
      integer, intent(in) :: ci(:), cj(:), m, nfree
      real(dp), intent(out) :: lambda(:), phi(:, :)
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: x(:, :), y(:, :), kr(:, :), mr(:, :), lam(:), lam_old(:), q(:, :), ky(:)
      real(dp) :: floor
      integer :: n, nq, it, i, j
      logical :: done

      n = size(mass)
      nq = min(nfree, max(2*m, m + 8))
      floor = rounding_floor*epsilon(1.0_dp)*scale
      call subspace_start(mass, nq, x, y, kr, mr, lam, lam_old, q, error, ky)
      if (allocated(error)) return
      done = .false.
      do it = 1, max_iterations
         do j = 1, nq
            y(:, j) = mass*x(:, j)
            call operator_apply(op, y(:, j), error)
            if (allocated(error)) return
         end do
         ! M-orthonormal columns (a collapsed column replaced by a fresh one in the null space)
         call m_orthonormalize(mass, y, it, 2, op)
         ! Ritz projection: kr = Y' (K + sum kd b b') Y, mr = Y' M Y
         do j = 1, nq
            call entry_product(ci, cj, cv, y(:, j), ky)
            do i = 1, j
               kr(i, j) = dot_product(y(:, i), ky)
            end do
         end do
         call ritz_vectors(mass, y, kr, mr, lam, q, x, error)
         if (allocated(error)) return
         done = it > 1
         if (done) done = subspace_settled(mass, x, phi, lam, lam_old, m, floor, floor)
         lam_old = lam
         phi(:, 1:m) = x(:, 1:m)
         if (done) exit
      end do
      call subspace_result(done, lam, m, lambda, phi, error)
   end subroutine constrained_subspace

   !> The arrays of a subspace iteration on q vectors and its start (start_vectors); ky, a
   !> vector of n, for an iteration that needs one.
   subroutine subspace_start(mass, nq, x, y, kr, mr, lam, lam_old, q, error, ky)
      real(dp), intent(in) :: mass(:)                          !! the masses, n = size(mass)
      integer, intent(in) :: nq                                !! vectors
      real(dp), allocatable, intent(out) :: x(:, :), y(:, :)   !! the iterates (n x q)
      real(dp), allocatable, intent(out) :: kr(:, :), mr(:, :) !! the projected K and M (q x q)
      real(dp), allocatable, intent(out) :: lam(:), lam_old(:) !! the Ritz values, now and before
      real(dp), allocatable, intent(out) :: q(:, :)            !! the projected eigenvectors
      type(error_type), allocatable, intent(out) :: error      !! no memory
      real(dp), allocatable, intent(out), optional :: ky(:)    !! a work vector
      integer :: n, stat

      n = size(mass)
      allocate (x(n, nq), y(n, nq), kr(nq, nq), mr(nq, nq), lam(nq), lam_old(nq), q(nq, nq), stat=stat)
      if (stat == 0 .and. present(ky)) allocate (ky(n), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the subspace iteration of the modes of "// &
                          trim(fmt_int(n))//" DOFs ("//trim(fmt_int(nq))//" vectors)", stat_no_memory)
         return
      end if
      call start_vectors(mass, x)
      lam_old = huge(1.0_dp)
   end subroutine subspace_start

   !> Rayleigh-Ritz on the M-orthonormal columns of y: mr = Y' M Y, kr (given on and above
   !> its diagonal) made symmetric, their eigenpairs (lam, q) and the Ritz vectors x = Y q.
   subroutine ritz_vectors(mass, y, kr, mr, lam, q, x, error)
      real(dp), intent(in) :: mass(:)                      !! the masses
      real(dp), intent(in) :: y(:, :)                      !! the vectors (n x q)
      real(dp), intent(inout) :: kr(:, :)                  !! Y' K Y (q x q), its upper part given
      real(dp), intent(out) :: mr(:, :)                    !! Y' M Y
      real(dp), intent(out) :: lam(:)                      !! the Ritz values, ascending
      real(dp), intent(out) :: q(:, :)                     !! their eigenvectors
      real(dp), intent(out) :: x(:, :)                     !! the Ritz vectors
      type(error_type), allocatable, intent(out) :: error  !! LAPACK failure
      integer :: i, j

      do j = 1, size(y, 2)
         do i = 1, j
            mr(i, j) = sum(mass*y(:, i)*y(:, j))
            kr(j, i) = kr(i, j)
            mr(j, i) = mr(i, j)
         end do
      end do
      call generalized_eigen(kr, mr, lam, q, error)
      if (allocated(error)) return
      x = matmul(y, q)
   end subroutine ritz_vectors

   !> The start vectors of a subspace iteration: the mass vector (it excites every DOF), then
   !> reproducible pseudo-random vectors.
   pure subroutine start_vectors(mass, x)
      real(dp), intent(in) :: mass(:)       !! the masses, n = size(mass)
      real(dp), intent(out) :: x(:, :)      !! n x q start vectors
      integer :: i, j

      x(:, 1) = mass
      do j = 2, size(x, 2)
         do i = 1, size(x, 1)
            x(i, j) = start_value(i, j)
         end do
      end do
   end subroutine start_vectors

   !> The columns of y made M-orthonormal in place by modified Gram-Schmidt, twice. A column
   !> that collapses is replaced by a fresh one (start_value of iteration it), projected on
   !> the constraints' null space when op is given, and orthogonalized fresh_passes times.
   subroutine m_orthonormalize(mass, y, it, fresh_passes, op)
      real(dp), intent(in) :: mass(:)                              !! the masses
      real(dp), intent(inout) :: y(:, :)                           !! n x q vectors
      integer, intent(in) :: it                                    !! the iteration
      integer, intent(in) :: fresh_passes                          !! passes for a fresh column
      type(constrained_operator), intent(inout), optional :: op    !! the constraints
      real(dp) :: norm
      integer :: nq, i, j

      nq = size(y, 2)
      do j = 1, nq
         call m_orthogonalize(mass, y, j, 2)
         norm = sqrt(sum(mass*y(:, j)**2))
         if (.not. (norm > 1.0e-12_dp*maxval(abs(y(:, j))) .and. norm > 0.0_dp)) then
            do i = 1, size(y, 1)
               y(i, j) = start_value(i, j + nq*it)
            end do
            if (present(op)) call operator_project(op, y(:, j))
            call m_orthogonalize(mass, y, j, fresh_passes)
            norm = sqrt(sum(mass*y(:, j)**2))
         end if
         y(:, j) = y(:, j)/norm
      end do
   end subroutine m_orthonormalize

   !> Column j of y made M-orthogonal to columns 1..j-1 (modified Gram-Schmidt, passes times).
   pure subroutine m_orthogonalize(mass, y, j, passes)
      real(dp), intent(in) :: mass(:)       !! the masses
      real(dp), intent(inout) :: y(:, :)    !! n x q vectors
      integer, intent(in) :: j              !! the column
      integer, intent(in) :: passes         !! how many times
      integer :: i, pass

      do pass = 1, passes
         do i = 1, j - 1
            y(:, j) = y(:, j) - sum(mass*y(:, i)*y(:, j))*y(:, i)
         end do
      end do
   end subroutine m_orthogonalize

   !> The end of a subspace iteration: the m wanted eigenvalues and shapes (the largest
   !> component of each positive), or an error when it did not settle.
   subroutine subspace_result(done, lam, m, lambda, phi, error)
      logical, intent(in) :: done                          !! it settled
      real(dp), intent(in) :: lam(:)                       !! the Ritz values
      integer, intent(in) :: m                             !! modes wanted
      real(dp), intent(inout) :: lambda(:)                 !! eigenvalues
      real(dp), intent(inout) :: phi(:, :)                 !! mode shapes (already the Ritz vectors)
      type(error_type), allocatable, intent(out) :: error  !! no convergence

      if (.not. done) then
         call fatal_error(error, "lowest_modes: the subspace iteration did not converge in "// &
                          trim(fmt_int(max_iterations))//" iterations (lambda_1 = "//trim(fmt_real(lam(1)))//")")
         return
      end if
      lambda(1:m) = lam(1:m)
      call positive_largest(phi(:, 1:m))
   end subroutine subspace_result

   !> Whether a subspace iteration has settled: each of the m wanted eigenvalues changed by at
   !> most max(lambda_tol |lambda|, lam_floor), and each wanted simple mode's shape (the M-norm
   !> of its change, up to sign) by at most max(vector_tol, vec_floor / its gap to its
   !> neighbours); a mode within cluster_tol of a neighbour has no shape of its own to settle.
   pure logical function subspace_settled(mass, x, phi, lam, lam_old, m, lam_floor, vec_floor) result(done)
      real(dp), intent(in) :: mass(:)      !! the masses
      real(dp), intent(in) :: x(:, :)      !! this iteration's Ritz vectors
      real(dp), intent(in) :: phi(:, :)    !! the last iteration's
      real(dp), intent(in) :: lam(:)       !! this iteration's Ritz values, ascending
      real(dp), intent(in) :: lam_old(:)   !! the last iteration's
      integer, intent(in) :: m             !! the wanted modes
      real(dp), intent(in) :: lam_floor    !! the least change of an eigenvalue that counts
      real(dp), intent(in) :: vec_floor    !! the round-off of a shape, times its gap
      real(dp) :: change, gap
      integer :: i, nq

      nq = size(lam)
      done = .true.
      do i = 1, m
         if (abs(lam(i) - lam_old(i)) > max(lambda_tol*abs(lam(i)), lam_floor)) done = .false.
      end do
      if (.not. done) return
      do i = 1, m
         gap = merge(lam(i) - lam(max(i - 1, 1)), huge(1.0_dp), i > 1)
         if (i < nq) gap = min(gap, lam(i + 1) - lam(i))
         if (gap <= cluster_tol*abs(lam(i))) cycle
         change = sign(1.0_dp, sum(mass*x(:, i)*phi(:, i)))
         change = sqrt(sum(mass*(x(:, i) - change*phi(:, i))**2))
         if (change > max(vector_tol, vec_floor/gap)) done = .false.
      end do
   end function subspace_settled

   !> A reproducible sign for each mode (column): its largest component positive.
   pure subroutine positive_largest(phi)
      real(dp), intent(inout) :: phi(:, :)  !! the modes
      integer :: i, j

      do i = 1, size(phi, 2)
         j = maxloc(abs(phi(:, i)), 1)
         if (phi(j, i) < 0.0_dp) phi(:, i) = -phi(:, i)
      end do
   end subroutine positive_largest

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
      real(dp), allocatable :: rs(:), dm(:), lam(:), phi(:, :)
      real(dp) :: x
      integer :: n, ne, i, a, b, stat

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
      allocate (rs(n), dm(n), stat=stat)
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
      ! Lanczos on A = D K D
      dm = 1.0_dp/sqrt(mass)
      call lanczos_largest(dm, bound, lambda, error, ei=ei, ej=ej, ek=ek)
   end subroutine highest_eigenvalue

   !> highest_eigenvalue of a general structure: K the springs and K_x, plus kd_d b_d b_d' of
   !> each device (matrix free, from their entries: O(nonzeros) a Lanczos step, no n x n
   !> matrix beyond modes_dense_max DOFs, where dsygv gives it exactly). The same bounds:
   !> lambda a lower bound (the largest Ritz value), bound Gershgorin's upper bound.
   subroutine general_highest_eigenvalue(mass, spring_i, spring_j, spring_k, kx_i, kx_j, kx_v, dev_ptr, dev_dof, &
                                         dev_coef, kd, lambda, bound, error)
      real(dp), intent(in) :: mass(:)             !! masses m_i > 0, n = size(mass)
      integer, intent(in) :: spring_i(:)          !! first node of each spring (0..n)
      integer, intent(in) :: spring_j(:)          !! second node of each spring (0..n, 0 = fixed)
      real(dp), intent(in) :: spring_k(:)         !! spring stiffness >= 0
      integer, intent(in) :: kx_i(:)              !! K_x: row of each entry (1..n)
      integer, intent(in) :: kx_j(:)              !! its column (kx_i <= kx_j)
      real(dp), intent(in) :: kx_v(:)             !! its value
      integer, intent(in) :: dev_ptr(:)           !! start of each device's terms (devices + 1)
      integer, intent(in) :: dev_dof(:)           !! DOF of each term
      real(dp), intent(in) :: dev_coef(:)         !! coefficient of each term
      real(dp), intent(in) :: kd(:)               !! each device's stiffness in K (>= 0; 0: none)
      real(dp), intent(out) :: lambda             !! largest Ritz value [1/s^2] (a lower bound)
      real(dp), intent(out) :: bound              !! Gershgorin bound [1/s^2] (an upper bound)
      type(error_type), allocatable, intent(out) :: error !! no memory, LAPACK failure
      integer, allocatable :: ci(:), cj(:)
      real(dp), allocatable :: cv(:), dm(:), q1(:), w(:), a(:, :), m(:, :), z(:, :)
      integer :: n, i, stat

      n = size(mass)
      lambda = 0.0_dp
      bound = 0.0_dp
      if (n == 0) return
      call stiffness_entries(n, spring_i, spring_j, spring_k, kx_i, kx_j, kx_v, dev_ptr, dev_dof, dev_coef, kd, &
                             ci, cj, cv, stat)
      if (stat == 0) allocate (dm(n), w(n), stat=stat)
      if (stat /= 0) then
         call no_memory(); return
      end if
      dm = 1.0_dp/sqrt(mass)
      ! Gershgorin on D K D, D = M^-1/2: the entries scaled, |K_ij| / sqrt(m_i m_j)
      call entry_rows(ci, cj, cv*dm(ci)*dm(cj), w)
      bound = maxval(w)
      if (bound == 0.0_dp) return
      if (n <= modes_dense_max) then   ! dsygv: every eigenvalue, the largest exact
         allocate (a(n, n), m(n, n), z(n, n), q1(n), stat=stat)
         if (stat /= 0) then
            call no_memory(); return
         end if
         m = 0.0_dp
         do i = 1, n
            q1 = 0.0_dp
            q1(i) = 1.0_dp
            call entry_product(ci, cj, cv, q1, a(:, i))
            m(i, i) = mass(i)
         end do
         call generalized_eigen(a, m, w, z, error)
         if (allocated(error)) return
         lambda = w(n)
         return
      end if
      call lanczos_largest(dm, bound, lambda, error, ci=ci, cj=cj, cv=cv)
   contains
      subroutine no_memory()
         call fatal_error(error, "highest_eigenvalue: not enough memory for "//trim(fmt_int(n))//" DOFs", &
                          stat_no_memory)
      end subroutine no_memory
   end subroutine general_highest_eigenvalue

   !> The largest Ritz value of A = D K D, D = M^-1/2 (dm its diagonal), by Lanczos from a
   !> reproducible pseudo-random start, at most bound: K from the elements (ei, ej, ek) or
   !> from its entries on and above the diagonal (ci, cj, cv).
   subroutine lanczos_largest(dm, bound, lambda, error, ei, ej, ek, ci, cj, cv)
      real(dp), intent(in) :: dm(:)                        !! D's diagonal, n = size(dm)
      real(dp), intent(in) :: bound                        !! Gershgorin bound of A
      real(dp), intent(out) :: lambda                      !! largest Ritz value
      type(error_type), allocatable, intent(out) :: error  !! no memory, dsterf failed
      integer, intent(in), optional :: ei(:), ej(:)        !! elements' nodes (0 = the table)
      real(dp), intent(in), optional :: ek(:)              !! elements' stiffness
      integer, intent(in), optional :: ci(:), cj(:)        !! entries' rows and columns
      real(dp), intent(in), optional :: cv(:)              !! entries' values
      real(dp), allocatable :: q0(:), q1(:), w(:), dq(:), alpha(:), beta(:), d(:), e(:)
      real(dp) :: nrm, top, prev
      integer :: n, i, k, info, stat

      n = size(dm)
      lambda = 0.0_dp
      allocate (q0(n), q1(n), w(n), dq(n), alpha(lanczos_max_steps), beta(lanczos_max_steps), &
                d(lanczos_max_steps), e(lanczos_max_steps), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "highest_eigenvalue: not enough memory for "//trim(fmt_int(n))//" DOFs", &
                          stat_no_memory)
         return
      end if
      do i = 1, n
         q1(i) = start_value(i, 1)
      end do
      q1 = q1/norm2(q1)
      q0 = 0.0_dp
      prev = -1.0_dp
      top = 0.0_dp
      do k = 1, min(lanczos_max_steps, n)
         ! w = D K D q1 - beta_(k-1) q0
         do i = 1, n
            dq(i) = dm(i)*q1(i)
         end do
         if (present(ek)) then
            call element_product(ei, ej, ek, dq, w)
         else
            call entry_product(ci, cj, cv, dq, w)
         end if
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
   end subroutine lanczos_largest

   !> y = K x for K given by its two-node elements (node 0 the table).
   pure subroutine element_product(ei, ej, ek, x, y)
      integer, intent(in) :: ei(:), ej(:)   !! the elements' nodes
      real(dp), intent(in) :: ek(:)         !! their stiffness
      real(dp), intent(in) :: x(:)          !! the vector
      real(dp), intent(out) :: y(:)         !! K x
      real(dp) :: f
      integer :: i, a, b

      y = 0.0_dp
      do i = 1, size(ek)
         a = ei(i); b = ej(i)
         f = 0.0_dp
         if (a > 0) f = x(a)
         if (b > 0) f = f - x(b)
         f = ek(i)*f
         if (a > 0) y(a) = y(a) + f
         if (b > 0) y(b) = y(b) - f
      end do
   end subroutine element_product

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
