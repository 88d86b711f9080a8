!> Polynomial kernels of the exact technique. Between events the solution of a phase
!> pattern is, on each sub-interval [0, L] of time s, its Taylor polynomial of degree K
!> plus a remainder that fd_phase_pattern bounds below the rounding level; every event
!> function and every output quantity is then a polynomial c(0) + c(1) s + ... + c(K) s^K.
!> These routines decide about such polynomials on [0, L]:
!>
!> - `poly_lower_bound`: a lower bound of p on [0, L] (the quadratic part exactly, the
!>   higher terms by their absolute values at L): if it is positive, p has no zero there.
!> - `descartes_count`: the number of sign variations of the coefficients of
!>   (1 + z)^d p(L / (1 + z)), an upper bound on the number of zeros of p in (0, L) that
!>   has the parity of that number (Descartes' rule of signs after the Moebius map
!>   (0, L) -> (0, inf); the Vincent-Collins-Akritas isolation, Collins and Akritas 1976):
!>   0 proves that there is none, 1 that there is exactly one.
!> - `first_crossing`: the first s in (0, L] with p(s) <= 0, given p(0) > 0: bisection of
!>   the interval, left half first, each piece excluded by the lower bound or by Descartes'
!>   rule, or isolated (one variation, a sign change) and the zero polished by safeguarded
!>   Newton; a piece shorter than the resolution is a zero only if p is <= 0 at its end.
!> - `stationary_points`: every zero of p' in (0, L), in increasing order, isolated the
!>   same way (for the exact extrema of the output quantities).
!>
!> Work arrays are passed in (no allocation); nothing here stops or prints.
module fd_taylor
   use fd_kinds, only: dp
   implicit none
   private

   public :: poly_value, poly_value_deriv, poly_shift, poly_abs_bound, poly_lower_bound, deriv_lower_bound
   public :: descartes_count, first_crossing, stationary_points, polish_zero, max_depth

   integer, parameter :: max_depth = 64   !! bisection levels of the isolation (work columns)

contains

   !> p(s) by Horner's rule.
   pure real(dp) function poly_value(c, s) result(v)
      real(dp), intent(in) :: c(0:)   !! coefficients
      real(dp), intent(in) :: s       !! abscissa
      integer :: k

      v = 0.0_dp
      do k = ubound(c, 1), 0, -1
         v = v*s + c(k)
      end do
   end function poly_value

   !> p(s) and p'(s) by Horner's rule.
   pure subroutine poly_value_deriv(c, s, v, dv)
      real(dp), intent(in) :: c(0:)   !! coefficients
      real(dp), intent(in) :: s       !! abscissa
      real(dp), intent(out) :: v      !! p(s)
      real(dp), intent(out) :: dv     !! p'(s)
      integer :: k

      v = 0.0_dp
      dv = 0.0_dp
      do k = ubound(c, 1), 0, -1
         dv = dv*s + v
         v = v*s + c(k)
      end do
   end subroutine poly_value_deriv

   !> Coefficients of p(s + h) (repeated synthetic division, O(K^2)); out may not alias c.
   pure subroutine poly_shift(c, h, out)
      real(dp), intent(in) :: c(0:)     !! coefficients of p
      real(dp), intent(in) :: h         !! shift
      real(dp), intent(out) :: out(0:)  !! coefficients of p(s + h), same degree
      integer :: i, j, n

      n = ubound(c, 1)
      out(0:n) = c(0:n)
      do i = 0, n - 1
         do j = n - 1, i, -1
            out(j) = out(j) + h*out(j + 1)
         end do
      end do
   end subroutine poly_shift

   !> sum_k |c(k)| L^k: a bound of |p| on [0, L].
   pure real(dp) function poly_abs_bound(c, len) result(b)
      real(dp), intent(in) :: c(0:)   !! coefficients
      real(dp), intent(in) :: len     !! interval length L >= 0
      integer :: k

      b = 0.0_dp
      do k = ubound(c, 1), 0, -1
         b = b*len + abs(c(k))
      end do
   end function poly_abs_bound

   !> A lower bound of sgn p on [0, L] (sgn = +1 or -1): the minimum of sgn (c0 + c1 s +
   !> c2 s^2) there, minus sum_{k >= 3} |c(k)| L^k.
   pure real(dp) function poly_lower_bound(c, len, sgn) result(b)
      real(dp), intent(in) :: c(0:)   !! coefficients (degree >= 0)
      real(dp), intent(in) :: len     !! interval length L >= 0
      real(dp), intent(in), optional :: sgn !! +1 (default) or -1
      real(dp) :: c0, c1, c2, tail, sg
      integer :: n, k

      sg = 1.0_dp
      if (present(sgn)) sg = sgn
      n = ubound(c, 1)
      c0 = sg*c(0)
      c1 = 0.0_dp
      c2 = 0.0_dp
      if (n >= 1) c1 = sg*c(1)
      if (n >= 2) c2 = sg*c(2)
      b = quadratic_min(c0, c1, c2, len)
      tail = 0.0_dp
      do k = n, 3, -1
         tail = tail*len + abs(c(k))
      end do
      if (n >= 3) tail = tail*len**3
      b = b - tail
   end function poly_lower_bound

   !> The minimum of c0 + c1 s + c2 s^2 over [0, L]: at an end, or at the vertex inside.
   pure real(dp) function quadratic_min(c0, c1, c2, len) result(b)
      real(dp), intent(in) :: c0, c1, c2  !! coefficients
      real(dp), intent(in) :: len         !! interval length L >= 0
      real(dp) :: sv

      b = min(c0, c0 + len*(c1 + len*c2))
      if (c2 > 0.0_dp) then
         sv = -c1/(2.0_dp*c2)
         if (sv > 0.0_dp .and. sv < len) b = min(b, c0 + sv*(c1 + sv*c2))
      end if
   end function quadratic_min

   !> A lower bound of sgn p' on [0, L], from the coefficients of p (poly_lower_bound of
   !> the derivative's coefficients (k + 1) c(k + 1)).
   pure real(dp) function deriv_lower_bound(c, len, sgn) result(b)
      real(dp), intent(in) :: c(0:)   !! coefficients of p (degree >= 1)
      real(dp), intent(in) :: len     !! interval length L >= 0
      real(dp), intent(in) :: sgn     !! +1 or -1
      real(dp) :: c0, c1, c2, tail
      integer :: n, k

      n = ubound(c, 1)
      b = 0.0_dp
      if (n < 1) return
      c0 = sgn*c(1)
      c1 = 0.0_dp
      c2 = 0.0_dp
      if (n >= 2) c1 = sgn*2.0_dp*c(2)
      if (n >= 3) c2 = sgn*3.0_dp*c(3)
      b = quadratic_min(c0, c1, c2, len)
      tail = 0.0_dp
      do k = n, 4, -1
         tail = tail*len + k*abs(c(k))
      end do
      if (n >= 4) tail = tail*len**3
      b = b - tail
   end function deriv_lower_bound

   !> Sign variations of the coefficients of (1 + z)^n p(L / (1 + z)), n = ubound(c): an
   !> upper bound on the number of zeros of p in (0, L), of the same parity.
   pure subroutine descartes_count(c, len, work, nv)
      real(dp), intent(in) :: c(0:)       !! coefficients of p
      real(dp), intent(in) :: len         !! interval length L > 0
      real(dp), intent(inout) :: work(0:) !! work (at least ubound(c) + 1)
      integer, intent(out) :: nv          !! sign variations
      integer :: n, i, j, last
      real(dp) :: lk

      n = ubound(c, 1)
      ! b(m) = c(n - m) L^(n - m): sum_j c(j) L^j (1 + z)^(n - j) = sum_m b(m) y^m at y = 1 + z
      lk = 1.0_dp
      do j = 0, n
         work(n - j) = c(j)*lk
         lk = lk*len
      end do
      do i = 0, n - 1
         do j = n - 1, i, -1
            work(j) = work(j) + work(j + 1)
         end do
      end do
      nv = 0
      last = 0
      do j = 0, n
         if (work(j) > 0.0_dp) then
            if (last < 0) nv = nv + 1
            last = 1
         else if (work(j) < 0.0_dp) then
            if (last > 0) nv = nv + 1
            last = -1
         end if
      end do
   end subroutine descartes_count

   !> The zero of sgn p in [lo, hi], given sgn p(lo) > 0 >= sgn p(hi) and one zero there:
   !> Newton's method safeguarded by bisection, until the bracket is no longer than tol or
   !> the Newton step is below tol/2 (then the sign change is pinned within tol of it).
   !> Returns a point at which sgn p <= 0, within tol after the zero.
   pure real(dp) function polish_zero(c, sgn, lo_in, hi_in, tol, flo, fhi) result(root)
      real(dp), intent(in) :: c(0:)   !! coefficients
      real(dp), intent(in) :: sgn     !! +1 or -1: the function is sgn p
      real(dp), intent(in) :: lo_in   !! sgn p(lo) > 0
      real(dp), intent(in) :: hi_in   !! sgn p(hi) <= 0
      real(dp), intent(in) :: tol     !! width at which to stop (> 0)
      real(dp), intent(in), optional :: flo, fhi !! p(lo), p(hi): a secant start
      real(dp) :: lo, hi, x, f, df, xn, b
      integer :: it

      lo = lo_in
      hi = hi_in
      x = 0.5_dp*(lo + hi)
      if (present(flo) .and. present(fhi)) then
         if (flo /= fhi) x = lo + (hi - lo)*flo/(flo - fhi)
         if (.not. (x > lo .and. x < hi)) x = 0.5_dp*(lo + hi)
      end if
      do it = 1, 200
         if (hi - lo <= tol) exit
         call poly_value_deriv(c, x, f, df)
         f = sgn*f
         df = sgn*df
         if (f > 0.0_dp) then
            lo = x
         else
            hi = x
         end if
         if (hi - lo <= tol) exit
         xn = 0.5_dp*(lo + hi)
         if (df /= 0.0_dp) then
            xn = x - f/df
            if (.not. (xn > lo .and. xn < hi)) xn = 0.5_dp*(lo + hi)
         end if
         if (abs(xn - x) <= 0.5_dp*tol) then
            ! converged: the sign change lies within tol of xn
            b = min(hi, xn + tol)
            if (sgn*poly_value(c, b) <= 0.0_dp) hi = b
            exit
         end if
         x = xn
      end do
      root = hi
   end function polish_zero

   !> The first s in (0, L] at which p(s) <= 0, given p(0) > 0 (found = .false. if none).
   !> Pieces shorter than smin are not split: there a zero is reported only if p <= 0 at
   !> the piece's end (a touch of zero within the resolution is no zero). tol is the width
   !> to which a zero is polished. work(0:, 0:max_depth) holds the shifted coefficients of
   !> each level, work2(0:) the Descartes transform.
   pure subroutine first_crossing(c, len, smin, tol, work, work2, s, found)
      real(dp), intent(in) :: c(0:)          !! coefficients of p about 0, p(0) > 0
      real(dp), intent(in) :: len            !! interval length L > 0
      real(dp), intent(in) :: smin           !! resolution: pieces shorter are not split
      real(dp), intent(in) :: tol            !! polishing width of a zero
      real(dp), intent(inout) :: work(0:, 0:) !! (0:K, 0:max_depth)
      real(dp), intent(inout) :: work2(0:)   !! (0:K)
      real(dp), intent(out) :: s             !! the first zero (if found)
      logical, intent(out) :: found          !! whether p reaches 0 in (0, L]
      real(dp) :: a(0:max_depth), w(0:max_depth), fe, wl
      integer :: side(0:max_depth)
      integer :: lev, n, nv
      logical :: settled

      n = ubound(c, 1)
      found = .false.
      s = len
      ! depth-first, left half first: level lev covers [a(lev), a(lev) + w(lev)] with the
      ! coefficients about a(lev) in work(:, lev); side -1: not examined, 0: split, left
      ! half next, 1: right half next, 2: both done
      lev = 0
      a(0) = 0.0_dp
      w(0) = len
      work(0:n, 0) = c(0:n)
      side(0) = -1
      do
         if (side(lev) == -1) then
            ! examine the piece: excluded, a zero isolated, or split
            settled = .true.
            wl = w(lev)
            if (work(0, lev) <= 0.0_dp) then
               ! p <= 0 at the start of a right half whose left neighbour was certified
               ! positive: a zero there, within rounding
               found = .true.
               s = a(lev)
            else if (poly_lower_bound(work(0:n, lev), wl) <= 0.0_dp) then
               fe = poly_value(work(0:n, lev), wl)
               if (deriv_lower_bound(work(0:n, lev), wl, -1.0_dp) > 0.0_dp .or. &
                   deriv_lower_bound(work(0:n, lev), wl, 1.0_dp) > 0.0_dp) then
                  ! p monotone over the piece: a zero iff p(L) <= 0
                  if (fe <= 0.0_dp) then
                     found = .true.
                     s = a(lev) + polish_zero(work(0:n, lev), 1.0_dp, 0.0_dp, wl, tol, work(0, lev), fe)
                  end if
               else
                  call descartes_count(work(0:n, lev), wl, work2, nv)
                  if (nv > 0) then
                     if ((nv == 1 .or. wl <= smin .or. lev == max_depth) .and. fe <= 0.0_dp) then
                        found = .true.
                        s = a(lev) + polish_zero(work(0:n, lev), 1.0_dp, 0.0_dp, wl, tol, work(0, lev), fe)
                     else if (wl > smin .and. lev < max_depth) then
                        settled = .false.
                     end if
                  end if
               end if
            end if
            if (found) return
            ! split the piece, or leave it (settled: as if both halves were done)
            side(lev) = merge(2, 0, settled)
         end if
         call next_piece(work, n, a, w, side, lev)
         if (lev < 0) return
      end do
   end subroutine first_crossing

   !> Every zero of p' in (0, L), increasing, into roots(1:nr) (at most size(roots); a
   !> piece shorter than smin that Descartes' rule cannot settle gives its midpoint, a
   !> candidate within the resolution). work(0:, 0:max_depth) and work2(0:) as in
   !> first_crossing; the derivative's coefficients are formed in work(:, 0).
   pure subroutine stationary_points(c, len, smin, tol, work, work2, roots, nr)
      real(dp), intent(in) :: c(0:)          !! coefficients of p about 0
      real(dp), intent(in) :: len            !! interval length L > 0
      real(dp), intent(in) :: smin           !! resolution
      real(dp), intent(in) :: tol            !! polishing width of a zero
      real(dp), intent(inout) :: work(0:, 0:) !! (0:K, 0:max_depth)
      real(dp), intent(inout) :: work2(0:)   !! (0:K)
      real(dp), intent(out) :: roots(:)      !! zeros of p'
      integer, intent(out) :: nr             !! their number
      real(dp) :: a(0:max_depth), w(0:max_depth), f0, fe, wl
      integer :: side(0:max_depth)
      integer :: lev, n, k, nv
      logical :: settled

      nr = 0
      n = ubound(c, 1) - 1
      if (n < 1) return     ! p' constant: no isolated zero
      do k = 0, n
         work(k, 0) = (k + 1)*c(k + 1)
      end do
      lev = 0
      a(0) = 0.0_dp
      w(0) = len
      side(0) = -1
      do
         if (side(lev) == -1) then
            settled = .true.
            if (nr < size(roots)) then
               wl = w(lev)
               ! the sign of p' just after the piece's start (its first nonzero coefficient:
               ! a zero at the start itself is no interior zero); all zero: p' = 0
               f0 = 0.0_dp
               do k = 0, n
                  if (work(k, lev) /= 0.0_dp) then
                     f0 = sign(1.0_dp, work(k, lev))
                     exit
                  end if
               end do
               ! p' bounded away from zero over the piece: no zero
               if (f0 /= 0.0_dp .and. (poly_lower_bound(work(0:n, lev), wl, f0) <= 0.0_dp .or. &
                                       work(0, lev) == 0.0_dp)) then
                  fe = poly_value(work(0:n, lev), wl)
                  if (deriv_lower_bound(work(0:n, lev), wl, 1.0_dp) > 0.0_dp .or. &
                      deriv_lower_bound(work(0:n, lev), wl, -1.0_dp) > 0.0_dp) then
                     ! p' monotone over the piece: a zero iff it changes sign
                     nv = 0
                     if (f0*fe <= 0.0_dp) nv = 1
                  else
                     call descartes_count(work(0:n, lev), wl, work2, nv)
                  end if
                  if (nv == 1 .and. f0*fe <= 0.0_dp) then
                     nr = nr + 1
                     roots(nr) = a(lev) + polish_zero(work(0:n, lev), f0, 0.0_dp, wl, tol, work(0, lev), fe)
                  else if (nv > 0 .and. (wl <= smin .or. lev == max_depth)) then
                     nr = nr + 1
                     roots(nr) = a(lev) + 0.5_dp*wl
                  else if (nv > 0) then
                     settled = .false.
                  end if
               end if
            end if
            ! split the piece, or leave it (settled: as if both halves were done)
            side(lev) = merge(2, 0, settled)
         end if
         call next_piece(work, n, a, w, side, lev)
         if (lev < 0) return
      end do
   end subroutine stationary_points

   !> One move of the left-first traversal of the bisection of [0, L] after the piece at
   !> level lev was split: into its left half (same coefficients), then into its right half
   !> (coefficients shifted to its start), then back up (lev < 0: the traversal is over).
   pure subroutine next_piece(work, n, a, w, side, lev)
      real(dp), intent(inout) :: work(0:, 0:)  !! coefficients of each level's piece
      integer, intent(in) :: n                 !! degree
      real(dp), intent(inout) :: a(0:), w(0:)  !! start and length of each level's piece
      integer, intent(inout) :: side(0:)       !! -1 new, 0 split, 1 left done, 2 both done
      integer, intent(inout) :: lev            !! current level

      if (side(lev) == 0) then
         side(lev) = 1
         work(0:n, lev + 1) = work(0:n, lev)
         a(lev + 1) = a(lev)
         w(lev + 1) = 0.5_dp*w(lev)
         lev = lev + 1
         side(lev) = -1
      else if (side(lev) == 1) then
         side(lev) = 2
         call poly_shift(work(0:n, lev), 0.5_dp*w(lev), work(0:n, lev + 1))
         a(lev + 1) = a(lev) + 0.5_dp*w(lev)
         w(lev + 1) = w(lev) - 0.5_dp*w(lev)
         lev = lev + 1
         side(lev) = -1
      else
         lev = lev - 1
      end if
   end subroutine next_piece

end module fd_taylor
