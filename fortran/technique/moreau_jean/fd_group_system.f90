!> The structure reduced to the groups of a sticking pattern: W_r = T' (alpha M + beta K) T,
!> with T the 0/1 matrix that gives every node of a moving group the group's value and the
!> nodes of the table's group zero (fd_stick_groups). K (springs) is kept as its element
!> list, so K x costs one pass over the springs, and W_r is assembled from it in band
!> storage for the groups' numbering and factored by LAPACK: `dpttrf` (tridiagonal L D L')
!> when the reduced band is 1 (a shear building, whatever sticks), `dpbtrf` (band Cholesky)
!> otherwise. Assembly, factorization and a solve cost O(n kb^2), O(n) for a chain.
!>
!> The band storage is sized at set-up for a half-bandwidth `capacity`; a pattern whose
!> groups need a wider band (a group spanning far apart nodes of a structure with several
!> columns) enlarges it, doubling, and counts it in `growths`: the only allocation after
!> set-up, never made for a chain.
module fd_group_system
   use fd_kinds, only: dp
   use fd_lapack, only: dpbtrf, dpbtrs, dpttrf, dpttrs, dsbgvx
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real, allocation_error
   implicit none
   private

   public :: group_system, gs_setup, gs_factor, gs_solve, gs_k_matvec, gs_k_absmatvec, gs_lowest_eigenvalue

   !> Springs, masses and the factor of the reduced system of one sticking pattern.
   type :: group_system
      integer :: n = 0                          !! DOFs
      integer :: ns = 0                         !! springs
      integer :: nr = 0                         !! size of the factored reduced system
      integer :: kb = 0                         !! its half-bandwidth
      integer :: capacity = 0                   !! half-bandwidth the storage holds
      integer :: growths = 0                    !! enlargements of the storage after set-up
      integer :: factorizations = 0             !! reduced systems assembled and factored
      logical :: factored = .false.             !! the factor is valid
      logical :: tridiagonal = .false.          !! factored by dpttrf (kb <= 1)
      integer, allocatable :: si(:), sj(:)      !! spring nodes (sj = 0: the table)
      real(dp), allocatable :: sk(:)            !! spring stiffness [N/m]
      real(dp), allocatable :: mass(:)          !! masses [kg]
      real(dp), allocatable :: ab(:)            !! band storage, (kb + 1) x nr, upper
      real(dp), allocatable :: dd(:), de(:)     !! tridiagonal factor (D, L's subdiagonal)
   end type group_system

contains

   !> Set up: springs and masses, storage for a reduced band up to `capacity`.
   subroutine gs_setup(gs, mass, si, sj, sk, capacity, error)
      type(group_system), intent(out) :: gs      !! the system
      real(dp), intent(in) :: mass(:)            !! masses [kg] (n = size)
      integer, intent(in) :: si(:)               !! first node of each spring (1..n)
      integer, intent(in) :: sj(:)               !! second node of each spring (0..n)
      real(dp), intent(in) :: sk(:)              !! spring stiffness [N/m]
      integer, intent(in) :: capacity            !! half-bandwidth to allocate for (>= 1)
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      integer :: stat

      gs%n = size(mass)
      gs%ns = size(si)
      gs%mass = mass
      gs%si = si
      gs%sj = sj
      gs%sk = sk
      gs%capacity = max(1, min(capacity, max(gs%n - 1, 1)))
      allocate (gs%ab((gs%capacity + 1)*gs%n), gs%dd(gs%n), gs%de(gs%n), stat=stat)
      call allocation_error(error, stat, trim(band_text(gs%n, gs%capacity)))
      if (allocated(error)) return
      gs%ab = 0.0_dp
      gs%dd = 0.0_dp
      gs%de = 0.0_dp
   end subroutine gs_setup

   !> Assemble W_r = T'(alpha M + beta K) T for the groups grp (0 = the table's) and factor it.
   subroutine gs_factor(gs, grp, nr, alpha, beta, error)
      type(group_system), intent(inout) :: gs    !! the system
      integer, intent(in) :: grp(0:)             !! group of each node (0:n)
      integer, intent(in) :: nr                  !! number of moving groups
      real(dp), intent(in) :: alpha              !! coefficient of M, > 0
      real(dp), intent(in) :: beta               !! coefficient of K, >= 0
      type(error_type), allocatable, intent(out) :: error !! not positive definite
      integer :: s, a, b, kb, ld, i, info, stat

      gs%factored = .false.
      gs%nr = nr
      if (nr == 0) then
         gs%factored = .true.
         return
      end if
      kb = reduced_bandwidth(gs, grp)
      gs%kb = kb
      gs%factorizations = gs%factorizations + 1
      if (kb <= 1) then
         gs%tridiagonal = .true.
         gs%dd(1:nr) = 0.0_dp
         gs%de(1:nr) = 0.0_dp
         do i = 1, gs%n
            if (grp(i) > 0) gs%dd(grp(i)) = gs%dd(grp(i)) + alpha*gs%mass(i)
         end do
         do s = 1, gs%ns
            a = grp(gs%si(s))
            b = grp(gs%sj(s))
            if (a == b) cycle
            if (a > 0) gs%dd(a) = gs%dd(a) + beta*gs%sk(s)
            if (b > 0) gs%dd(b) = gs%dd(b) + beta*gs%sk(s)
            if (a > 0 .and. b > 0) gs%de(min(a, b)) = gs%de(min(a, b)) - beta*gs%sk(s)
         end do
         call dpttrf(nr, gs%dd, gs%de, info)
      else
         gs%tridiagonal = .false.
         if (kb > gs%capacity) then
            do while (gs%capacity < kb)
               gs%capacity = min(2*gs%capacity, gs%n - 1)
            end do
            deallocate (gs%ab)
            allocate (gs%ab((gs%capacity + 1)*gs%n), stat=stat)
            call allocation_error(error, stat, trim(band_text(gs%n, gs%capacity)))
            if (allocated(error)) return
            gs%growths = gs%growths + 1
         end if
         ld = kb + 1
         gs%ab(1:ld*nr) = 0.0_dp
         ! A(i, j), i <= j, at ab(ld (j - 1) + kb + 1 + i - j)
         do i = 1, gs%n
            if (grp(i) > 0) then
               a = ld*(grp(i) - 1) + ld
               gs%ab(a) = gs%ab(a) + alpha*gs%mass(i)
            end if
         end do
         do s = 1, gs%ns
            a = grp(gs%si(s))
            b = grp(gs%sj(s))
            if (a == b) cycle
            if (a > 0) gs%ab(ld*a) = gs%ab(ld*a) + beta*gs%sk(s)
            if (b > 0) gs%ab(ld*b) = gs%ab(ld*b) + beta*gs%sk(s)
            if (a > 0 .and. b > 0) then
               i = ld*(max(a, b) - 1) + ld + min(a, b) - max(a, b)
               gs%ab(i) = gs%ab(i) - beta*gs%sk(s)
            end if
         end do
         call dpbtrf('U', nr, kb, gs%ab, ld, info)
      end if
      if (info /= 0) then
         call fatal_error(error, "the reduced system of the sticking pattern is not positive definite "// &
                          "(pivot "//trim(fmt_int(info))//" of "//trim(fmt_int(nr))//", alpha = "// &
                          trim(fmt_real(alpha))//", beta = "//trim(fmt_real(beta))//")")
         return
      end if
      gs%factored = .true.
   end subroutine gs_factor

   !> Solve W_r x = b with the current factor; b (nr) is overwritten by x.
   subroutine gs_solve(gs, b)
      type(group_system), intent(in) :: gs       !! the system (factored)
      real(dp), intent(inout) :: b(:)            !! right-hand side, then solution (size >= nr)
      integer :: info

      if (gs%nr == 0) return
      if (gs%tridiagonal) then
         call dpttrs(gs%nr, 1, gs%dd, gs%de, b, gs%nr, info)
      else
         call dpbtrs('U', gs%nr, gs%kb, 1, gs%ab, gs%kb + 1, b, gs%nr, info)
      end if
   end subroutine gs_solve

   !> y = alpha K x + beta y over the springs (y not read when beta = 0).
   pure subroutine gs_k_matvec(gs, x, y, alpha, beta)
      type(group_system), intent(in) :: gs      !! the system
      real(dp), intent(in) :: x(:)               !! nodal vector (n)
      real(dp), intent(inout) :: y(:)            !! result (n)
      real(dp), intent(in) :: alpha              !! factor of K x
      real(dp), intent(in) :: beta               !! factor of y
      integer :: s, i, j
      real(dp) :: f

      if (beta == 0.0_dp) then
         y = 0.0_dp
      else if (beta /= 1.0_dp) then
         y = beta*y
      end if
      do s = 1, gs%ns
         i = gs%si(s)
         j = gs%sj(s)
         f = x(i)
         if (j > 0) f = f - x(j)
         f = alpha*gs%sk(s)*f
         y(i) = y(i) + f
         if (j > 0) y(j) = y(j) - f
      end do
   end subroutine gs_k_matvec

   !> y = y + |alpha| |K| |x| over the springs (the size of the terms of K x, for tolerances).
   pure subroutine gs_k_absmatvec(gs, x, y, alpha)
      type(group_system), intent(in) :: gs      !! the system
      real(dp), intent(in) :: x(:)               !! nodal vector (n)
      real(dp), intent(inout) :: y(:)            !! accumulated sizes (n)
      real(dp), intent(in) :: alpha              !! factor
      integer :: s, i, j
      real(dp) :: f

      do s = 1, gs%ns
         i = gs%si(s)
         j = gs%sj(s)
         f = abs(x(i))
         if (j > 0) f = f + abs(x(j))
         f = abs(alpha)*gs%sk(s)*f
         y(i) = y(i) + f
         if (j > 0) y(j) = y(j) + f
      end do
   end subroutine gs_k_absmatvec

   !> Lowest eigenvalue w^2 of T'K T z = w^2 T'M T z for the groups grp (LAPACK dsbgvx on the
   !> reduced band: bisection for the one eigenvalue). Set-up only: it allocates.
   subroutine gs_lowest_eigenvalue(gs, grp, nr, lam, lam_scale, error)
      type(group_system), intent(in) :: gs       !! the system
      integer, intent(in) :: grp(0:)             !! group of each node (0:n)
      integer, intent(in) :: nr                  !! number of moving groups (>= 1)
      real(dp), intent(out) :: lam               !! lowest eigenvalue [1/s2]
      real(dp), intent(out) :: lam_scale         !! max K_ii / M_ii of the reduced system (>= the
                                                 !! largest eigenvalue / 2: the scale of lam)
      type(error_type), allocatable, intent(out) :: error !! LAPACK failure
      real(dp), allocatable :: ab(:, :), bb(:, :), w(:), work(:), q(:, :), z(:, :)
      integer, allocatable :: iwork(:), ifail(:)
      integer :: s, a, b, kb, i, m, info, stat

      kb = reduced_bandwidth(gs, grp)
      allocate (ab(kb + 1, nr), bb(1, nr), w(nr), work(7*nr), iwork(5*nr), ifail(nr), q(1, 1), z(1, 1), &
                stat=stat)
      call allocation_error(error, stat, trim(band_text(gs%n, kb)))
      if (allocated(error)) return
      ab = 0.0_dp
      bb = 0.0_dp
      do i = 1, gs%n
         if (grp(i) > 0) bb(1, grp(i)) = bb(1, grp(i)) + gs%mass(i)
      end do
      do s = 1, gs%ns
         a = grp(gs%si(s))
         b = grp(gs%sj(s))
         if (a == b) cycle
         if (a > 0) ab(kb + 1, a) = ab(kb + 1, a) + gs%sk(s)
         if (b > 0) ab(kb + 1, b) = ab(kb + 1, b) + gs%sk(s)
         if (a > 0 .and. b > 0) ab(kb + 1 + min(a, b) - max(a, b), max(a, b)) = &
            ab(kb + 1 + min(a, b) - max(a, b), max(a, b)) - gs%sk(s)
      end do
      lam_scale = maxval(ab(kb + 1, :)/bb(1, :))
      call dsbgvx('N', 'I', 'U', nr, kb, 0, ab, kb + 1, bb, 1, q, 1, 0.0_dp, 0.0_dp, 1, 1, &
                  2.0_dp*tiny(1.0_dp), m, w, z, 1, work, iwork, ifail, info)
      if (info /= 0 .or. m < 1) then
         call fatal_error(error, "the lowest eigenvalue of the stuck system was not found (LAPACK dsbgvx info = "// &
                          trim(fmt_int(info))//")")
         lam = 0.0_dp
         return
      end if
      lam = w(1)
   end subroutine gs_lowest_eigenvalue

   !> Half-bandwidth of T'K T for the groups grp: the largest |grp(i) - grp(j)| over the
   !> springs joining two moving groups.
   pure integer function reduced_bandwidth(gs, grp) result(kb)
      type(group_system), intent(in) :: gs       !! the system
      integer, intent(in) :: grp(0:)             !! group of each node (0:n)
      integer :: s, a, b

      kb = 0
      do s = 1, gs%ns
         a = grp(gs%si(s))
         b = grp(gs%sj(s))
         if (a > 0 .and. b > 0 .and. a /= b) kb = max(kb, abs(a - b))
      end do
   end function reduced_bandwidth

   !> What a band's memory is for, in a message: "the reduced band system of n DOFs
   !> (half-bandwidth kb)".
   pure function band_text(n, kb) result(text)
      integer, intent(in) :: n                      !! rows
      integer, intent(in) :: kb                     !! half-bandwidth
      character(len=80) :: text
      text = "the reduced band system of "//trim(fmt_int(n))//" DOFs (half-bandwidth "//trim(fmt_int(kb))//")"
   end function band_text

end module fd_group_system
