!> Matrix exponential by scaling and squaring with the degree-13 Pade approximant
!> (Higham, SIAM J. Matrix Anal. Appl. 26, 2005), and the Van Loan block exponential that
!> gives the exact propagators of a linear time-invariant system with polynomial input.
module fd_expm
   use fd_kinds, only: dp
   use fd_linalg, only: lu_solve
   implicit none
   private

   public :: expm, lti_propagators

   real(dp), parameter :: theta13 = 5.371920351148152_dp
   real(dp), parameter :: b(0:13) = [64764752532480000.0_dp, 32382376266240000.0_dp, &
      7771770303897600.0_dp, 1187353796428800.0_dp, 129060195264000.0_dp, 10559470521600.0_dp, &
      670442572800.0_dp, 33522128640.0_dp, 1323241920.0_dp, 40840800.0_dp, 960960.0_dp, &
      16380.0_dp, 182.0_dp, 1.0_dp]


contains

   !> E = exp(A).
   subroutine expm(a, e, info)
      real(dp), intent(in) :: a(:, :)     !! square matrix
      real(dp), intent(out) :: e(:, :)    !! exp(a)
      integer, intent(out) :: info        !! 0, or the LAPACK failure of the Pade solve
      real(dp), allocatable :: as(:, :), a2(:, :), a4(:, :), a6(:, :), u(:, :), v(:, :)
      integer, allocatable :: ipiv(:)
      real(dp) :: nrm
      integer :: n, s, i

      n = size(a, 1)
      info = 0
      if (n == 0) return
      nrm = maxval(sum(abs(a), dim=1))
      s = 0
      if (nrm > theta13) s = max(0, ceiling(log(nrm/theta13)/log(2.0_dp)))
      as = a/2.0_dp**s
      a2 = matmul(as, as)
      a4 = matmul(a2, a2)
      a6 = matmul(a4, a2)
      u = matmul(a6, b(13)*a6 + b(11)*a4 + b(9)*a2) + b(7)*a6 + b(5)*a4 + b(3)*a2
      v = matmul(a6, b(12)*a6 + b(10)*a4 + b(8)*a2) + b(6)*a6 + b(4)*a4 + b(2)*a2
      do i = 1, n
         u(i, i) = u(i, i) + b(1)
         v(i, i) = v(i, i) + b(0)
      end do
      u = matmul(as, u)
      ! (V - U) E = (V + U)
      e = v + u
      v = v - u
      allocate (ipiv(n))
      call lu_solve(v, e, ipiv, info)
      if (info /= 0) return
      do i = 1, s
         e = matmul(e, e)
      end do
   end subroutine expm

   !> Propagators of x' = A x + g(t) over a time tau, from one block exponential:
   !>   exp([[A, I, 0], [0, 0, I], [0, 0, 0]] tau) = [[phi, gam1, gam2], [0, I, tau I], [0, 0, I]]
   !> phi = exp(A tau), gam1 = int_0^tau exp(A s) ds, gam2 = int_0^tau exp(A (tau - s)) s ds,
   !> so that x(tau) = phi x(0) + gam1 (g0) + gam2 (g1) for g(t) = g0 + g1 t.
   subroutine lti_propagators(a, tau, phi, gam1, gam2, info)
      real(dp), intent(in) :: a(:, :)        !! state matrix (m x m)
      real(dp), intent(in) :: tau            !! time step
      real(dp), intent(out) :: phi(:, :)     !! exp(A tau)
      real(dp), intent(out) :: gam1(:, :)    !! response to a constant input
      real(dp), intent(out) :: gam2(:, :)    !! response to a ramp input
      integer, intent(out) :: info           !! 0, or failure of expm
      real(dp), allocatable :: big(:, :), e(:, :)
      integer :: m, i

      m = size(a, 1)
      info = 0
      if (m == 0) return
      allocate (big(3*m, 3*m), e(3*m, 3*m))
      big = 0.0_dp
      big(1:m, 1:m) = a*tau
      do i = 1, m
         big(i, m + i) = tau
         big(m + i, 2*m + i) = tau
      end do
      call expm(big, e, info)
      phi = e(1:m, 1:m)
      gam1 = e(1:m, m + 1:2*m)
      gam2 = e(1:m, 2*m + 1:3*m)
   end subroutine lti_propagators

end module fd_expm
