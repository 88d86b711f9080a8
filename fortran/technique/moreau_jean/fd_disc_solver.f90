!> Planar Coulomb friction in the one-step problem of Moreau-Jean time stepping: a planar
!> bearing's impulse lies in a disc instead of an interval.
!>
!> With the impulses lambda of the devices and their end-of-step relative velocities
!>   w = q - A lambda
!> (A = B' W^-1 B the Delassus operator, q = B' W^-1 r the velocities without friction), a
!> one-dimensional device d satisfies |lambda_d| <= g_d, w_d = 0 or lambda_d = g_d sgn(w_d),
!> and a bearing b (two components, the block A_bb) satisfies
!>   |lambda_b| <= g_b,   w_b = 0  or  lambda_b = g_b w_b / |w_b|          (g = h P mu).
!>
!> disc_local solves one bearing alone (c = its free velocity, the others' impulses held):
!> it sticks when |A_bb^-1 c| <= g (lambda = A_bb^-1 c); otherwise it slides with
!> lambda = g e, w = s e (|e| = 1, s = |w| > 0), i.e. c = (s I + g A_bb) e: in the
!> eigenbasis of A_bb (alpha_1, alpha_2, c') the slip speed s is the one root of
!>   phi(s)^2 = sum_i c'_i^2 / (s + g alpha_i)^2 = 1,
!> decreasing and convex in s, bracketed by |c| - g alpha_max <= s <= |c| - g alpha_min and
!> found by Newton's method from the left end (monotone, quadratic); an isotropic block or c
!> along an eigenvector gives the closed form s = |c'| - g alpha exactly.
!>
!> disc_gauss_seidel solves several bearings and one-dimensional devices together by
!> projected block Gauss-Seidel over the devices, each block by its exact local solution
!> (a 1D device: c / a_dd clipped to [-g, g]); the dual of the one-step problem is a convex
!> quadratic program over a product of discs and intervals, on which block Gauss-Seidel
!> converges (Luo and Tseng 1992). Sweeps stop when no impulse changed by more than tol times
!> the largest bound in a sweep; a cap on the sweeps is reported to the caller, never
!> returned as an answer.
module fd_disc_solver
   use fd_kinds, only: dp
   implicit none
   private

   public :: disc_local, disc_gauss_seidel
   public :: disc_ok, disc_not_definite, disc_unconverged

   integer, parameter :: disc_ok = 0             !! solved
   integer, parameter :: disc_not_definite = 1   !! a diagonal block not positive definite
   integer, parameter :: disc_unconverged = 2    !! the sweeps' cap reached

   integer, parameter :: max_newton = 100        !! Newton steps of the slip speed (monotone: a few)

contains

   !> One bearing: lam in the disc |lam| <= g and w = c - a lam with w = 0 or lam = g w/|w|.
   !> status: disc_ok, or disc_not_definite when a is not positive definite.
   pure subroutine disc_local(a, c, g, lam, w, status)
      real(dp), intent(in) :: a(2, 2)               !! the bearing's block of A (symmetric)
      real(dp), intent(in) :: c(2)                  !! its velocity with its own impulse 0
      real(dp), intent(in) :: g                     !! the disc's radius h P mu, >= 0
      real(dp), intent(out) :: lam(2)               !! its impulse
      real(dp), intent(out) :: w(2)                 !! its end-of-step relative velocity
      integer, intent(out) :: status                !! disc_ok or disc_not_definite
      real(dp) :: q(2, 2), al(2), cp(2), lp(2), s

      lam = 0.0_dp
      w = c
      call eigen2(a, q, al)
      status = disc_not_definite
      if (.not. (al(1) > 0.0_dp .and. al(2) > 0.0_dp)) return
      status = disc_ok
      if (g <= 0.0_dp .or. (c(1) == 0.0_dp .and. c(2) == 0.0_dp)) return
      cp = matmul(transpose(q), c)
      ! stick: the impulse that stops the bearing lies in the disc
      lp = cp/al
      if (hypot(lp(1), lp(2)) <= g) then
         lam = matmul(q, lp)
         w = c - matmul(a, lam)
         return
      end if
      ! slip: the speed s with |(s I + g A) ^-1 c| = 1, e along the sliding direction
      call slip_speed(al, cp, g, s)
      lp = cp/(s + g*al)
      lp = lp/hypot(lp(1), lp(2))
      lam = g*matmul(q, lp)
      w = c - matmul(a, lam)
   end subroutine disc_local

   !> The root s >= 0 of sum_i cp_i^2 / (s + g al_i)^2 = 1 (slip: its value at s = 0 exceeds 1).
   !> An isotropic block or cp along an eigenvector: s = |cp| - g al in closed form; otherwise
   !> Newton's method from the bracket's left end, monotone for this convex decreasing function.
   pure subroutine slip_speed(al, cp, g, s)
      real(dp), intent(in) :: al(2), cp(2), g
      real(dp), intent(out) :: s
      real(dp) :: f, df, ds, d1, d2, cn
      integer :: it

      cn = hypot(cp(1), cp(2))
      if (cp(2) == 0.0_dp .or. cp(1) == 0.0_dp .or. al(1) == al(2)) then
         if (cp(2) == 0.0_dp) then
            s = abs(cp(1)) - g*al(1)
         else if (cp(1) == 0.0_dp) then
            s = abs(cp(2)) - g*al(2)
         else
            s = cn - g*al(1)
         end if
         s = max(s, 0.0_dp)
         return
      end if
      s = max(cn - g*max(al(1), al(2)), 0.0_dp)
      do it = 1, max_newton
         d1 = s + g*al(1)
         d2 = s + g*al(2)
         f = (cp(1)/d1)**2 + (cp(2)/d2)**2 - 1.0_dp
         if (f <= 0.0_dp) exit
         df = -2.0_dp*((cp(1)/d1)**2/d1 + (cp(2)/d2)**2/d2)
         ds = -f/df
         s = s + ds
         if (ds <= 4.0_dp*epsilon(1.0_dp)*(s + g*max(al(1), al(2)))) exit
      end do
   end subroutine slip_speed

   !> Eigenvectors (columns of q) and eigenvalues al of a symmetric 2 x 2 matrix (a Jacobi
   !> rotation; q = I when a is diagonal).
   pure subroutine eigen2(a, q, al)
      real(dp), intent(in) :: a(2, 2)
      real(dp), intent(out) :: q(2, 2), al(2)
      real(dp) :: tau, t, cs, sn, off

      off = 0.5_dp*(a(1, 2) + a(2, 1))
      if (off == 0.0_dp) then
         q = reshape([1.0_dp, 0.0_dp, 0.0_dp, 1.0_dp], [2, 2])
         al = [a(1, 1), a(2, 2)]
         return
      end if
      tau = (a(2, 2) - a(1, 1))/(2.0_dp*off)
      t = sign(1.0_dp, tau)/(abs(tau) + sqrt(1.0_dp + tau*tau))
      cs = 1.0_dp/sqrt(1.0_dp + t*t)
      sn = t*cs
      al = [a(1, 1) - t*off, a(2, 2) + t*off]
      q = reshape([cs, -sn, sn, cs], [2, 2])
   end subroutine eigen2

   !> Several devices together: projected block Gauss-Seidel on w = q - a lam, every block
   !> (a 1D device, or a bearing's two entries d and partner(d)) by its exact local solution,
   !> from the impulses lam given (a warm start). Stops when a sweep changed no impulse by
   !> more than tol max(g); status disc_unconverged after max_sweeps (lam then the last
   !> sweep's), disc_not_definite for a block that is not positive definite.
   pure subroutine disc_gauss_seidel(a, q, g, partner, tol, max_sweeps, lam, w, sweeps, change, status)
      real(dp), intent(in) :: a(:, :)               !! (m, m) the Delassus operator
      real(dp), intent(in) :: q(:)                  !! (m) the velocities without friction
      real(dp), intent(in) :: g(:)                  !! (m) the bounds (a bearing's two equal)
      integer, intent(in) :: partner(:)             !! (m) a bearing's other entry, 0 for a 1D device
      real(dp), intent(in) :: tol                   !! the sweeps' stop, relative to max(g)
      integer, intent(in) :: max_sweeps             !! their cap
      real(dp), intent(inout) :: lam(:)             !! (m) impulses: the start, then the solution
      real(dp), intent(out) :: w(:)                 !! (m) q - a lam
      integer, intent(out) :: sweeps                !! sweeps made
      real(dp), intent(out) :: change               !! the last sweep's largest change / max(g)
      integer, intent(out) :: status                !! disc_ok, disc_unconverged, disc_not_definite
      integer :: m, i, j
      real(dp) :: scale, c2(2), l2(2), w2(2), c1, l1, dl

      m = size(q)
      status = disc_ok
      sweeps = 0
      change = 0.0_dp
      w = q
      if (m == 0) return
      scale = maxval(g)
      if (scale <= 0.0_dp) then
         lam = 0.0_dp
         return
      end if
      do
         sweeps = sweeps + 1
         dl = 0.0_dp
         do i = 1, m
            j = partner(i)
            if (j > 0 .and. j < i) cycle
            if (j == 0) then
               c1 = q(i) - dot_product(a(i, :), lam) + a(i, i)*lam(i)
               if (.not. a(i, i) > 0.0_dp) then
                  status = disc_not_definite
                  return
               end if
               l1 = max(-g(i), min(g(i), c1/a(i, i)))
               dl = max(dl, abs(l1 - lam(i)))
               lam(i) = l1
            else
               c2(1) = q(i) - dot_product(a(i, :), lam) + a(i, i)*lam(i) + a(i, j)*lam(j)
               c2(2) = q(j) - dot_product(a(j, :), lam) + a(j, i)*lam(i) + a(j, j)*lam(j)
               call disc_local(reshape([a(i, i), a(j, i), a(i, j), a(j, j)], [2, 2]), c2, g(i), l2, w2, status)
               if (status /= disc_ok) return
               dl = max(dl, abs(l2(1) - lam(i)), abs(l2(2) - lam(j)))
               lam(i) = l2(1)
               lam(j) = l2(2)
            end if
         end do
         change = dl/scale
         if (change <= tol) exit
         if (sweeps >= max_sweeps) then
            status = disc_unconverged
            exit
         end if
      end do
      ! w = q - a lam, without a temporary for the product
      do i = 1, m
         w(i) = q(i) - dot_product(a(i, :), lam)
      end do
   end subroutine disc_gauss_seidel

end module fd_disc_solver
