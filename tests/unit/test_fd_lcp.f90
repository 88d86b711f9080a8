!> Unit tests of the linear complementarity solvers (fd_lcp): hand-solved problems, random
!> problems where Lemke's method, the enumeration of patterns and projected Gauss-Seidel
!> must agree, problems without a solution, and the box LCP of Coulomb friction against
!> closed forms and a brute-force search over every stick/slide pattern of the mechanics.
!> Every solution is checked here, independently of the solver's own residual.
module test_fd_lcp
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use fd_error, only: fmt_real, fmt_int, fd_error_type => error_type
   use fd_linalg, only: lu_solve
   use fd_lcp, only: lcp_work, lcp_info, lcp_init, lcp_solve, lcp_lemke, lcp_enumerate, lcp_pgs, &
                     box_lcp_solve, box_lcp_lemke, box_lcp_enumerate, box_lcp_pgs, lcp_residual, &
                     box_lcp_residual, lcp_status_text, lcp_solved, lcp_infeasible, lcp_ray, &
                     lcp_pivot_limit, lcp_not_converged, lcp_inaccurate, lcp_too_large, lcp_bad_input
   implicit none
   private

   public :: collect_lcp

   real(dp), parameter :: ctol = 1.0e-12_dp  !! feasibility and complementarity, relative
   real(dp), parameter :: atol = 1.0e-11_dp  !! agreement of two methods on a unique solution, relative
   character(len=12), parameter :: names(4) = [character(len=12) :: 'lemke', 'enumeration', 'pgs', 'solve']

   !> Park-Miller minimal standard generator: reproducible on every platform.
   type :: rng_type
      integer(8) :: s = 1
   end type rng_type

contains

   subroutine collect_lcp(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("hand-solved 2x2", test_hand_2x2), &
                  new_unittest("hand-solved 3x3", test_hand_3x3), &
                  new_unittest("degenerate w_i = z_i = 0", test_degenerate), &
                  new_unittest("random SPD: Lemke = enumeration = PGS", test_random_spd), &
                  new_unittest("nonsymmetric P-matrix", test_p_matrix), &
                  new_unittest("no solution: reported, never answered", test_no_solution), &
                  new_unittest("random general M: never a wrong answer", test_random_general), &
                  new_unittest("pivot limit, bad input, status texts", test_limits), &
                  new_unittest("n = 200 SPD, box n = 100", test_large), &
                  new_unittest("box: two devices in parallel", test_box_parallel), &
                  new_unittest("box: block on a moving table", test_box_table), &
                  new_unittest("box: 5-mass chain vs all 3^5 patterns", test_box_chain), &
                  new_unittest("box: random SPD and singular PSD", test_box_random), &
                  new_unittest("box: random general M always solvable", test_box_general), &
                  new_unittest("box: subnormal data, bounds of 1", test_box_subnormal) &
                  ]
   end subroutine collect_lcp

   ! ------------------------------------------------------------------ helpers

   function uniform(rng, a, b) result(x)
      type(rng_type), intent(inout) :: rng
      real(dp), intent(in) :: a, b
      real(dp) :: x

      rng%s = mod(16807_8*rng%s, 2147483647_8)
      x = a + (b - a)*real(rng%s, dp)/2147483647.0_dp
   end function uniform

   subroutine seed(rng, k)
      type(rng_type), intent(out) :: rng
      integer, intent(in) :: k
      real(dp) :: x
      integer :: i

      rng%s = 12345_8 + 7919_8*k
      do i = 1, 5
         x = uniform(rng, 0.0_dp, 1.0_dp)
      end do
   end subroutine seed

   !> M = R'R + shift I with R uniform in [-1, 1] (rank-deficient R when rows < n).
   subroutine random_gram(rng, n, rows, shift, m)
      type(rng_type), intent(inout) :: rng
      integer, intent(in) :: n, rows
      real(dp), intent(in) :: shift
      real(dp), intent(out) :: m(:, :)
      real(dp) :: r(rows, n)
      integer :: i, j

      do j = 1, n
         do i = 1, rows
            r(i, j) = uniform(rng, -1.0_dp, 1.0_dp)
         end do
      end do
      m = matmul(transpose(r), r)
      do i = 1, n
         m(i, i) = m(i, i) + shift
      end do
   end subroutine random_gram

   !> Scales of z and w for relative checks.
   subroutine scales(m, q, z, zs, ws, lo, hi)
      real(dp), intent(in) :: m(:, :), q(:), z(:)
      real(dp), intent(out) :: zs, ws
      real(dp), intent(in), optional :: lo(:), hi(:)
      integer :: i

      zs = maxval(abs(z))
      if (present(lo)) zs = max(zs, maxval(abs(lo)), maxval(abs(hi)))
      if (zs == 0.0_dp) zs = 1.0_dp
      ws = 0.0_dp
      do i = 1, size(q)
         ws = max(ws, abs(q(i)) + sum(abs(m(i, :)*z)))
      end do
      if (ws == 0.0_dp) ws = 1.0_dp
   end subroutine scales

   !> Independent check of a standard LCP solution: w = M z + q, z >= 0, w >= 0, z'w = 0.
   subroutine check_lcp(error, m, q, z, w, what)
      type(error_type), allocatable, intent(out) :: error
      real(dp), intent(in) :: m(:, :), q(:), z(:), w(:)
      character(len=*), intent(in) :: what
      real(dp) :: zs, ws, wc(size(q))
      integer :: i

      call scales(m, q, z, zs, ws)
      wc = matmul(m, z) + q
      do i = 1, size(q)
         if (abs(w(i) - wc(i)) > ctol*ws) then
            call check(error, .false., trim(what)//': w /= M z + q at '//fmt_int(i))
         else if (z(i) < -ctol*zs .or. wc(i) < -ctol*ws) then
            call check(error, .false., trim(what)//': infeasible at '//trim(fmt_int(i))//': z = '// &
                       trim(fmt_real(z(i)))//', w = '//trim(fmt_real(wc(i))))
         else if (min(z(i)/zs, wc(i)/ws) > ctol) then
            call check(error, .false., trim(what)//': not complementary at '//trim(fmt_int(i))//': z = '// &
                       trim(fmt_real(z(i)))//', w = '//trim(fmt_real(wc(i))))
         end if
         if (allocated(error)) return
      end do
   end subroutine check_lcp

   !> Independent check of a box LCP solution: lo <= z <= hi, z above lo => w <= 0,
   !> z below hi => w >= 0.
   subroutine check_box(error, m, q, lo, hi, z, w, what)
      type(error_type), allocatable, intent(out) :: error
      real(dp), intent(in) :: m(:, :), q(:), lo(:), hi(:), z(:), w(:)
      character(len=*), intent(in) :: what
      real(dp) :: zs, ws, wc(size(q))
      integer :: i

      call scales(m, q, z, zs, ws, lo, hi)
      wc = matmul(m, z) + q
      do i = 1, size(q)
         if (abs(w(i) - wc(i)) > ctol*ws) then
            call check(error, .false., trim(what)//': w /= M z + q at '//fmt_int(i))
         else if (z(i) < lo(i) - ctol*zs .or. z(i) > hi(i) + ctol*zs) then
            call check(error, .false., trim(what)//': z out of bounds at '//trim(fmt_int(i))//': '// &
                       trim(fmt_real(z(i))))
         else if (z(i) > lo(i) + ctol*zs .and. wc(i) > ctol*ws) then
            call check(error, .false., trim(what)//': z above lo with w > 0 at '//trim(fmt_int(i))// &
                       ': z = '//trim(fmt_real(z(i)))//', w = '//trim(fmt_real(wc(i))))
         else if (z(i) < hi(i) - ctol*zs .and. wc(i) < -ctol*ws) then
            call check(error, .false., trim(what)//': z below hi with w < 0 at '//trim(fmt_int(i))// &
                       ': z = '//trim(fmt_real(z(i)))//', w = '//trim(fmt_real(wc(i))))
         end if
         if (allocated(error)) return
      end do
   end subroutine check_box

   subroutine check_status(error, info, expected, what)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_info), intent(in) :: info
      integer, intent(in) :: expected
      character(len=*), intent(in) :: what

      if (info%status /= expected) call check(error, .false., trim(what)//': status '//trim(fmt_int(info%status))// &
                                              ' ('//trim(lcp_status_text(info%status))//'), expected '// &
                                              trim(fmt_int(expected)))
   end subroutine check_status

   !> max |a - b| <= tol max(1, |b|)
   subroutine check_near(error, a, b, tol, what)
      type(error_type), allocatable, intent(out) :: error
      real(dp), intent(in) :: a(:), b(:), tol
      character(len=*), intent(in) :: what
      real(dp) :: d

      d = maxval(abs(a - b))
      if (d > tol*max(1.0_dp, maxval(abs(b)))) call check(error, .false., trim(what)//': differ by '//trim(fmt_real(d)))
   end subroutine check_near

   subroutine new_work(error, work, nmax, pmax)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work), intent(out) :: work
      integer, intent(in) :: nmax, pmax
      type(fd_error_type), allocatable :: err

      call lcp_init(work, nmax, pmax, err)
      if (allocated(err)) call check(error, .false., 'lcp_init: '//err%message)
   end subroutine new_work

   !> Solve by one method (1 Lemke, 2 enumeration, 3 PGS from z = 0, 4 lcp_solve); check
   !> the status, the solution and the residual reported.
   subroutine solve_checked(error, work, k, m, q, z, w, what)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work), intent(inout) :: work
      integer, intent(in) :: k
      real(dp), intent(in) :: m(:, :), q(:)
      real(dp), intent(out) :: z(:), w(:)
      character(len=*), intent(in) :: what
      type(lcp_info) :: info

      select case (k)
      case (1)
         call lcp_lemke(work, m, q, z, w, info)
      case (2)
         call lcp_enumerate(work, m, q, z, w, info)
      case (3)
         z = 0.0_dp
         call lcp_pgs(work, m, q, z, w, info)
      case default
         call lcp_solve(work, m, q, z, w, info)
      end select
      call check_status(error, info, lcp_solved, what//' '//trim(names(k)))
      if (allocated(error)) return
      call check_lcp(error, m, q, z, w, what//' '//trim(names(k)))
      if (allocated(error)) return
      if (info%residual /= lcp_residual(m, q, z, w)) &
         call check(error, .false., what//' '//trim(names(k))//': reported residual is not that of z')
   end subroutine solve_checked

   !> Solve by each method listed, check each, and check that they agree on z (a problem
   !> with a unique solution).
   subroutine methods_agree(error, work, methods, m, q, what)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work), intent(inout) :: work
      integer, intent(in) :: methods(:)
      real(dp), intent(in) :: m(:, :), q(:)
      character(len=*), intent(in) :: what
      real(dp) :: z(size(q)), w(size(q)), zref(size(q))
      integer :: c

      do c = 1, size(methods)
         call solve_checked(error, work, methods(c), m, q, z, w, what)
         if (allocated(error)) return
         if (c == 1) then
            zref = z
         else
            call check_near(error, z, zref, atol, what//' '//trim(names(methods(c)))//' vs '// &
                            trim(names(methods(1))))
            if (allocated(error)) return
         end if
      end do
   end subroutine methods_agree

   !> Standard LCP by every method, each checked, with the expected z and w.
   subroutine all_methods(error, work, m, q, zx, wx, what, pgs)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work), intent(inout) :: work
      real(dp), intent(in) :: m(:, :), q(:), zx(:), wx(:)
      character(len=*), intent(in) :: what
      logical, intent(in) :: pgs
      real(dp) :: z(size(q)), w(size(q)), tol
      integer :: k

      do k = 1, 4
         if (k == 3 .and. .not. pgs) cycle
         call solve_checked(error, work, k, m, q, z, w, what)
         if (allocated(error)) return
         ! direct methods to round-off; PGS to its stopping residual
         tol = merge(1.0e-9_dp, 1.0e-14_dp, k == 3)
         call check_near(error, z, zx, tol, what//' '//trim(names(k))//' z')
         if (allocated(error)) return
         call check_near(error, w, wx, tol, what//' '//trim(names(k))//' w')
         if (allocated(error)) return
      end do
   end subroutine all_methods

   ! ------------------------------------------------------------------ standard LCP

   subroutine test_hand_2x2(error)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work) :: work
      real(dp) :: m(2, 2)

      call new_work(error, work, 4, 4)
      if (allocated(error)) return
      work%pgs_tol = 1.0e-14_dp
      m = reshape([2.0_dp, 1.0_dp, 1.0_dp, 2.0_dp], [2, 2])
      ! both positive: z = M^-1 (5, 6) = (4/3, 7/3)
      call all_methods(error, work, m, [-5.0_dp, -6.0_dp], [4.0_dp/3.0_dp, 7.0_dp/3.0_dp], [0.0_dp, 0.0_dp], &
                       '2x2 both', .true.)
      if (allocated(error)) return
      ! one positive: z1 = 1/2, w2 = 1/2 + 2
      call all_methods(error, work, m, [-1.0_dp, 2.0_dp], [0.5_dp, 0.0_dp], [0.0_dp, 2.5_dp], '2x2 one', .true.)
      if (allocated(error)) return
      ! q >= 0: z = 0
      call all_methods(error, work, m, [1.0_dp, 3.0_dp], [0.0_dp, 0.0_dp], [1.0_dp, 3.0_dp], '2x2 none', .true.)
   end subroutine test_hand_2x2

   subroutine test_hand_3x3(error)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work) :: work
      real(dp) :: m(3, 3)

      call new_work(error, work, 3, 3)
      if (allocated(error)) return
      work%pgs_tol = 1.0e-14_dp
      ! tridiagonal: z2 = 0, z1 = z3 = 3/4, w2 = -3/4 + 2 - 3/4
      m = reshape([4.0_dp, -1.0_dp, 0.0_dp, -1.0_dp, 4.0_dp, -1.0_dp, 0.0_dp, -1.0_dp, 4.0_dp], [3, 3])
      call all_methods(error, work, m, [-3.0_dp, 2.0_dp, -3.0_dp], [0.75_dp, 0.0_dp, 0.75_dp], &
                       [0.0_dp, 0.5_dp, 0.0_dp], '3x3 tridiagonal', .true.)
      if (allocated(error)) return
      ! Murty's cycling example (nonsymmetric P-matrix, every ratio test ties at the start):
      ! z = (1, 1, 1)/3, w = 0
      m = transpose(reshape([1.0_dp, 2.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 2.0_dp, 2.0_dp, 0.0_dp, 1.0_dp], [3, 3]))
      call all_methods(error, work, m, [-1.0_dp, -1.0_dp, -1.0_dp], [1.0_dp, 1.0_dp, 1.0_dp]/3.0_dp, &
                       [0.0_dp, 0.0_dp, 0.0_dp], '3x3 cycling example', .false.)
   end subroutine test_hand_3x3

   subroutine test_degenerate(error)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work) :: work
      real(dp) :: m2(2, 2), m3(3, 3)
      integer :: i

      call new_work(error, work, 3, 3)
      if (allocated(error)) return
      work%pgs_tol = 1.0e-14_dp
      ! z = (1, 0), w = (0, 0): index 2 has w = z = 0
      m2 = reshape([2.0_dp, 1.0_dp, 1.0_dp, 2.0_dp], [2, 2])
      call all_methods(error, work, m2, [-2.0_dp, -1.0_dp], [1.0_dp, 0.0_dp], [0.0_dp, 0.0_dp], &
                       'degenerate 2x2', .true.)
      if (allocated(error)) return
      ! identity with q3 = 0: w3 = z3 = 0
      m3 = 0.0_dp
      do i = 1, 3
         m3(i, i) = 1.0_dp
      end do
      call all_methods(error, work, m3, [-1.0_dp, -1.0_dp, 0.0_dp], [1.0_dp, 1.0_dp, 0.0_dp], &
                       [0.0_dp, 0.0_dp, 0.0_dp], 'degenerate identity', .true.)
      if (allocated(error)) return
      ! q = 0: z = 0, w = 0, every index degenerate
      m3 = 1.0_dp
      do i = 1, 3
         m3(i, i) = 2.0_dp
      end do
      call all_methods(error, work, m3, [0.0_dp, 0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp, 0.0_dp], &
                       [0.0_dp, 0.0_dp, 0.0_dp], 'degenerate q = 0', .true.)
      if (allocated(error)) return
      ! I + J, q = -1: all ratios tie, z = (1, 1, 1)/4
      call all_methods(error, work, m3, [-1.0_dp, -1.0_dp, -1.0_dp], [0.25_dp, 0.25_dp, 0.25_dp], &
                       [0.0_dp, 0.0_dp, 0.0_dp], 'degenerate ties', .true.)
      if (allocated(error)) return
      call test_cycling(error)
   end subroutine test_degenerate

   !> A degenerate LCP on which Lemke's method cycles for ever when ties in the ratio test
   !> go to the first row, the last row or the largest pivot (found by a search over small
   !> integer problems); the lexicographic rule solves it in 4 pivots. Its solutions are
   !> z = (0, 1, 0, 0) and z = (0, 3, 2, 0)/5.
   subroutine test_cycling(error)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work) :: work
      real(dp) :: m(4, 4), q(4), z(4), w(4)
      type(lcp_info) :: info

      call new_work(error, work, 4, 4)
      if (allocated(error)) return
      m = transpose(reshape([0.0_dp, 3.0_dp, 2.0_dp, 1.0_dp, 3.0_dp, 1.0_dp, 1.0_dp, -2.0_dp, &
                             -1.0_dp, 3.0_dp, -2.0_dp, 1.0_dp, 1.0_dp, 2.0_dp, 2.0_dp, -1.0_dp], [4, 4]))
      q = -1.0_dp
      call lcp_lemke(work, m, q, z, w, info)
      call check_status(error, info, lcp_solved, 'cycling example')
      if (allocated(error)) return
      call check_lcp(error, m, q, z, w, 'cycling example')
      if (allocated(error)) return
      call check(error, maxval(abs(z - [0.0_dp, 1.0_dp, 0.0_dp, 0.0_dp])) <= 1.0e-14_dp .or. &
                 maxval(abs(z - [0.0_dp, 0.6_dp, 0.4_dp, 0.0_dp])) <= 1.0e-14_dp, 'cycling example: z')
   end subroutine test_cycling

   !> Symmetric positive definite M (a P-matrix: unique z): the three methods agree.
   subroutine test_random_spd(error)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work) :: work
      type(rng_type) :: rng
      real(dp), allocatable :: m(:, :), q(:)
      integer :: n, k, i
      character(len=96) :: what

      call new_work(error, work, 8, 8)
      if (allocated(error)) return
      work%pgs_tol = 1.0e-14_dp
      work%pgs_max_sweeps = 100000
      do n = 1, 8
         allocate (m(n, n), q(n))
         do k = 1, 150
            call seed(rng, 1000*n + k)
            call random_gram(rng, n, n, 0.5_dp, m)
            do i = 1, n
               q(i) = uniform(rng, -1.0_dp, 1.0_dp)
            end do
            what = 'n = '//trim(fmt_int(n))//' seed '//trim(fmt_int(k))
            call methods_agree(error, work, [2, 1, 3], m, q, trim(what))
            if (allocated(error)) return
         end do
         deallocate (m, q)
      end do
   end subroutine test_random_spd

   !> Nonsymmetric P-matrices, not positive semidefinite: Lemke finds the unique solution.
   subroutine test_p_matrix(error)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work) :: work
      type(rng_type) :: rng
      real(dp) :: m2(2, 2)
      real(dp), allocatable :: m(:, :), q(:)
      integer :: n, k, i, j
      character(len=96) :: what

      call new_work(error, work, 8, 8)
      if (allocated(error)) return
      ! [[1, 4], [0, 1]]: x'Mx = -2 at x = (1, -1), principal minors 1, 1, 1
      m2 = transpose(reshape([1.0_dp, 4.0_dp, 0.0_dp, 1.0_dp], [2, 2]))
      ! w2 = z2 - 1 forces z2 = 1; w1 = z1 + 3 > 0 forces z1 = 0
      call all_methods(error, work, m2, [-1.0_dp, -1.0_dp], [0.0_dp, 1.0_dp], [3.0_dp, 0.0_dp], &
                       'P 2x2 a', .false.)
      if (allocated(error)) return
      call all_methods(error, work, m2, [-1.0_dp, 2.0_dp], [1.0_dp, 0.0_dp], [0.0_dp, 2.0_dp], &
                       'P 2x2 b', .false.)
      if (allocated(error)) return
      ! random strictly row diagonally dominant with a positive diagonal: P-matrices
      do n = 1, 8
         allocate (m(n, n), q(n))
         do k = 1, 100
            call seed(rng, 5000 + 100*n + k)
            do j = 1, n
               do i = 1, n
                  m(i, j) = uniform(rng, -1.0_dp, 1.0_dp)
               end do
            end do
            do i = 1, n
               m(i, i) = sum(abs(m(i, :))) - abs(m(i, i)) + uniform(rng, 0.1_dp, 1.0_dp)
               q(i) = uniform(rng, -1.0_dp, 1.0_dp)
            end do
            what = 'P n = '//trim(fmt_int(n))//' seed '//trim(fmt_int(k))
            call methods_agree(error, work, [2, 1], m, q, trim(what))
            if (allocated(error)) return
         end do
         deallocate (m, q)
      end do
   end subroutine test_p_matrix

   subroutine test_no_solution(error)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work) :: work
      real(dp) :: m1(1, 1), m2(2, 2), z1(1), w1(1), z2(2), w2(2)
      type(lcp_info) :: info

      call new_work(error, work, 4, 4)
      if (allocated(error)) return
      ! w = -z - 1 < 0 for every z >= 0
      m1 = -1.0_dp
      call lcp_lemke(work, m1, [-1.0_dp], z1, w1, info)
      call check(error, info%status /= lcp_solved, '1x1: Lemke claims a solution')
      if (allocated(error)) return
      call lcp_enumerate(work, m1, [-1.0_dp], z1, w1, info)
      call check_status(error, info, lcp_infeasible, '1x1 enumeration')
      if (allocated(error)) return
      call lcp_solve(work, m1, [-1.0_dp], z1, w1, info)
      call check_status(error, info, lcp_infeasible, '1x1 solve')
      if (allocated(error)) return
      ! symmetric positive semidefinite, singular: w1 + w2 = -2 < 0; Lemke's ray proves it
      m2 = reshape([1.0_dp, -1.0_dp, -1.0_dp, 1.0_dp], [2, 2])
      call lcp_lemke(work, m2, [-1.0_dp, -1.0_dp], z2, w2, info)
      call check_status(error, info, lcp_ray, 'PSD lemke')
      if (allocated(error)) return
      call lcp_enumerate(work, m2, [-1.0_dp, -1.0_dp], z2, w2, info)
      call check_status(error, info, lcp_infeasible, 'PSD enumeration')
      if (allocated(error)) return
      call lcp_solve(work, m2, [-1.0_dp, -1.0_dp], z2, w2, info)
      call check_status(error, info, lcp_infeasible, 'PSD solve')
      if (allocated(error)) return
      ! skew-symmetric (positive semidefinite, not symmetric): w2 = -z1 - 1 < 0
      m2 = reshape([0.0_dp, -1.0_dp, 1.0_dp, 0.0_dp], [2, 2])
      call lcp_lemke(work, m2, [-1.0_dp, -1.0_dp], z2, w2, info)
      call check_status(error, info, lcp_ray, 'skew lemke')
      if (allocated(error)) return
      call lcp_solve(work, m2, [-1.0_dp, -1.0_dp], z2, w2, info)
      call check_status(error, info, lcp_infeasible, 'skew solve')
      if (allocated(error)) return
      ! the same skew matrix with a feasible q has a solution: w1 = z2 - 1, w2 = 1 - z1
      call all_methods(error, work, m2, [-1.0_dp, 1.0_dp], [1.0_dp, 1.0_dp], [0.0_dp, 0.0_dp], 'skew feasible', &
                       .false.)
   end subroutine test_no_solution

   !> Random general (indefinite, nonsymmetric) M: whatever the solver returns is right. A
   !> brute force over all patterns (LAPACK LU, independent of fd_lcp) decides solvability.
   subroutine test_random_general(error)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work) :: work
      type(rng_type) :: rng
      real(dp), allocatable :: m(:, :), q(:), z(:), w(:)
      type(lcp_info) :: info
      integer :: n, k, i, j, solved, infeasible
      logical :: exists
      character(len=96) :: what

      call new_work(error, work, 6, 6)
      if (allocated(error)) return
      work%tol = ctol
      solved = 0
      infeasible = 0
      do n = 1, 6
         allocate (m(n, n), q(n), z(n), w(n))
         do k = 1, 200
            call seed(rng, 20000 + 1000*n + k)
            do j = 1, n
               do i = 1, n
                  m(i, j) = uniform(rng, -1.0_dp, 1.0_dp)
               end do
               q(j) = uniform(rng, -1.0_dp, 1.0_dp)
            end do
            what = 'general n = '//trim(fmt_int(n))//' seed '//trim(fmt_int(k))
            exists = brute_force_exists(m, q)
            call lcp_solve(work, m, q, z, w, info)
            if (info%status == lcp_solved) then
               solved = solved + 1
               call check_lcp(error, m, q, z, w, trim(what))
               if (allocated(error)) return
               call check(error, exists, trim(what)//': solved, but the brute force finds no solution')
               if (allocated(error)) return
            else
               call check_status(error, info, lcp_infeasible, trim(what))
               if (allocated(error)) return
               infeasible = infeasible + 1
               call check(error, .not. exists, trim(what)//': reported infeasible, but the brute force solves it')
               if (allocated(error)) return
            end if
         end do
         deallocate (m, q, z, w)
      end do
      ! the family must exercise both answers
      call check(error, solved > 100 .and. infeasible > 20, 'general: '//trim(fmt_int(solved))//' solved, '// &
                 trim(fmt_int(infeasible))//' infeasible')
   end subroutine test_random_general

   !> Does LCP(q, M) have a solution? All 2^n patterns, each free block by LAPACK.
   function brute_force_exists(m, q) result(exists)
      real(dp), intent(in) :: m(:, :), q(:)
      logical :: exists
      integer :: n, mask, k, i, info
      integer, allocatable :: f(:), ipiv(:)
      real(dp), allocatable :: a(:, :), b(:, :), z(:), w(:)

      n = size(q)
      exists = .false.
      allocate (w(n))
      do mask = 0, 2**n - 1
         f = pack([(i, i=1, n)], [(btest(mask, i - 1), i=1, n)])
         k = size(f)
         allocate (z(n))
         z = 0.0_dp
         if (k > 0) then
            a = m(f, f)
            b = reshape(-q(f), [k, 1])
            allocate (ipiv(k))
            call lu_solve(a, b, ipiv, info)
            deallocate (ipiv)
            if (info /= 0) then
               deallocate (z)
               cycle
            end if
            z(f) = b(:, 1)
         end if
         w = matmul(m, z) + q
         if (all(z >= -1.0e-9_dp) .and. all(w >= -1.0e-9_dp)) exists = .true.
         deallocate (z)
         if (exists) return
      end do
   end function brute_force_exists

   subroutine test_limits(error)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work) :: work, none
      type(fd_error_type), allocatable :: err
      real(dp) :: m3(3, 3), q3(3), z3(3), w3(3), z2(2), z4(4), w4(4), m4(4, 4), q4(4)
      real(dp) :: nan, zero
      type(lcp_info) :: info
      integer :: i, j

      call new_work(error, work, 3, 3)
      if (allocated(error)) return
      m3 = 0.0_dp
      do i = 1, 3
         m3(i, i) = 1.0_dp
      end do
      q3 = -1.0_dp
      ! M = I, q = -1 takes n + 1 pivots: a cap of 2 stops it
      work%max_pivots = 2
      call lcp_lemke(work, m3, q3, z3, w3, info)
      call check_status(error, info, lcp_pivot_limit, 'cap 2')
      if (allocated(error)) return
      call check(error, info%iterations == 2, 'cap 2: pivots '//fmt_int(info%iterations))
      if (allocated(error)) return
      work%max_pivots = 0
      call lcp_lemke(work, m3, q3, z3, w3, info)
      call check_status(error, info, lcp_solved, 'no cap')
      if (allocated(error)) return
      call check(error, info%iterations == 4, 'no cap: pivots '//fmt_int(info%iterations))
      if (allocated(error)) return
      ! bad input: n > nmax, sizes, NaN, lo > hi, M_ii = 0 for PGS, no workspace
      m4 = 0.0_dp
      q4 = 1.0_dp
      call lcp_lemke(work, m4, q4, z4, w4, info)
      call check_status(error, info, lcp_bad_input, 'n > nmax')
      if (allocated(error)) return
      call lcp_lemke(work, m3, q3, z2, w3, info)
      call check_status(error, info, lcp_bad_input, 'size(z) /= n')
      if (allocated(error)) return
      zero = 0.0_dp
      nan = ieee_value(zero, ieee_quiet_nan)   ! not 0/0: a build that traps invalid stops there
      q3(2) = nan
      call lcp_solve(work, m3, q3, z3, w3, info)
      call check_status(error, info, lcp_bad_input, 'NaN in q')
      if (allocated(error)) return
      q3 = -1.0_dp
      call box_lcp_solve(work, m3, q3, [0.0_dp, 1.0_dp, 0.0_dp], [1.0_dp, 0.0_dp, 1.0_dp], z3, w3, info)
      call check_status(error, info, lcp_bad_input, 'lo > hi')
      if (allocated(error)) return
      m3(2, 2) = 0.0_dp
      z3 = 0.0_dp
      call lcp_pgs(work, m3, q3, z3, w3, info)
      call check_status(error, info, lcp_bad_input, 'PGS with M_22 = 0')
      if (allocated(error)) return
      call lcp_solve(none, m3, q3, z3, w3, info)
      call check_status(error, info, lcp_bad_input, 'no workspace')
      if (allocated(error)) return
      call lcp_init(none, 0, 0, err)
      call check(error, allocated(err), 'lcp_init accepts nmax = 0')
      if (allocated(error)) return
      call lcp_init(none, 3, 4, err)
      call check(error, allocated(err), 'lcp_init accepts pivot_max > nmax')
      if (allocated(error)) return
      ! a PGS-only workspace refuses pivoting, runs PGS
      call lcp_init(none, 3, 0, err)
      call check(error, .not. allocated(err), 'lcp_init(3, 0) fails')
      if (allocated(error)) return
      m3(2, 2) = 1.0_dp
      call lcp_lemke(none, m3, q3, z3, w3, info)
      call check_status(error, info, lcp_bad_input, 'Lemke beyond pivot_max')
      if (allocated(error)) return
      z3 = 0.0_dp
      call lcp_pgs(none, m3, q3, z3, w3, info)
      call check_status(error, info, lcp_solved, 'PGS-only workspace')
      if (allocated(error)) return
      ! enumeration beyond its limit
      work%enum_max = 2
      call lcp_enumerate(work, m3, q3, z3, w3, info)
      call check_status(error, info, lcp_too_large, 'enumeration limit')
      if (allocated(error)) return
      ! PGS that cannot converge in its sweeps says so
      do j = 1, 3
         do i = 1, 3
            m3(i, j) = 0.999_dp
         end do
         m3(j, j) = 1.0_dp
      end do
      work%pgs_max_sweeps = 3
      work%pgs_tol = 1.0e-14_dp
      z3 = 0.0_dp
      call lcp_pgs(work, m3, [-1.0_dp, -2.0_dp, -3.0_dp], z3, w3, info)
      call check_status(error, info, lcp_not_converged, 'PGS sweep cap')
      if (allocated(error)) return
      ! the residual check is applied to every answer: with a negative tolerance none passes
      work%tol = -1.0_dp
      work%enum_max = 12
      call lcp_lemke(work, m3, [-1.0_dp, -2.0_dp, -3.0_dp], z3, w3, info)
      call check_status(error, info, lcp_inaccurate, 'Lemke, tol < 0')
      if (allocated(error)) return
      call box_lcp_lemke(work, m3, [-1.0_dp, -2.0_dp, -3.0_dp], [-1.0_dp, -1.0_dp, -1.0_dp], &
                         [1.0_dp, 1.0_dp, 1.0_dp], z3, w3, info)
      call check_status(error, info, lcp_inaccurate, 'box Lemke, tol < 0')
      if (allocated(error)) return
      call lcp_enumerate(work, m3, [-1.0_dp, -2.0_dp, -3.0_dp], z3, w3, info)
      call check(error, info%status /= lcp_solved, 'enumeration, tol < 0: solved')
      if (allocated(error)) return
      call box_lcp_solve(work, m3, [-1.0_dp, -2.0_dp, -3.0_dp], [-1.0_dp, -1.0_dp, -1.0_dp], &
                         [1.0_dp, 1.0_dp, 1.0_dp], z3, w3, info)
      call check(error, info%status /= lcp_solved, 'box solve, tol < 0: solved')
      if (allocated(error)) return
      ! every status has its own text
      do i = lcp_solved, lcp_bad_input
         do j = lcp_solved, i - 1
            call check(error, lcp_status_text(i) /= lcp_status_text(j), 'status texts equal: '//fmt_int(i))
            if (allocated(error)) return
         end do
      end do
   end subroutine test_limits

   !> Lemke at the sizes of a building (n = 200; box n = 100, a tableau of 200 rows)
   !> against PGS.
   subroutine test_large(error)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work) :: work
      type(rng_type) :: rng
      integer, parameter :: n = 200, nb = 100
      real(dp), allocatable :: m(:, :), q(:), z1(:), w1(:), z2(:), w2(:), lo(:), hi(:)
      type(lcp_info) :: info
      integer :: i

      call new_work(error, work, n, n)
      if (allocated(error)) return
      work%pgs_tol = 1.0e-14_dp
      allocate (m(n, n), q(n), z1(n), w1(n), z2(n), w2(n))
      call seed(rng, 77)
      call random_gram(rng, n, n, 0.0_dp, m)
      m = m/real(n, dp)
      do i = 1, n
         m(i, i) = m(i, i) + 0.5_dp
         q(i) = uniform(rng, -1.0_dp, 1.0_dp)
      end do
      call lcp_lemke(work, m, q, z1, w1, info)
      call check_status(error, info, lcp_solved, 'n = 200 lemke')
      if (allocated(error)) return
      call check_lcp(error, m, q, z1, w1, 'n = 200 lemke')
      if (allocated(error)) return
      z2 = 0.0_dp
      call lcp_pgs(work, m, q, z2, w2, info)
      call check_status(error, info, lcp_solved, 'n = 200 pgs')
      if (allocated(error)) return
      call check_near(error, z1, z2, atol, 'n = 200 lemke vs pgs')
      if (allocated(error)) return
      call check(error, count(z1 > 0.0_dp) > 20 .and. count(z1 == 0.0_dp) > 20, 'n = 200: a mixed pattern')
      if (allocated(error)) return
      ! box, n = 100
      allocate (lo(nb), hi(nb))
      do i = 1, nb
         lo(i) = -uniform(rng, 0.05_dp, 0.5_dp)
         hi(i) = -lo(i)
      end do
      call box_lcp_lemke(work, m(1:nb, 1:nb), q(1:nb), lo, hi, z1(1:nb), w1(1:nb), info)
      call check_status(error, info, lcp_solved, 'box n = 100 lemke')
      if (allocated(error)) return
      call check_box(error, m(1:nb, 1:nb), q(1:nb), lo, hi, z1(1:nb), w1(1:nb), 'box n = 100 lemke')
      if (allocated(error)) return
      z2 = 0.0_dp
      call box_lcp_pgs(work, m(1:nb, 1:nb), q(1:nb), lo, hi, z2(1:nb), w2(1:nb), info)
      call check_status(error, info, lcp_solved, 'box n = 100 pgs')
      if (allocated(error)) return
      call check_near(error, z1(1:nb), z2(1:nb), atol, 'box n = 100 lemke vs pgs')
      if (allocated(error)) return
      call check(error, count(abs(z1(1:nb)) < hi) > 10 .and. count(abs(z1(1:nb)) == hi) > 10, &
                 'box n = 100: sticking and sliding devices')
   end subroutine test_large

   ! ------------------------------------------------------------------ box LCP: friction

   !> Box LCP by every method, each checked.
   subroutine box_all(error, work, m, q, lo, hi, z, w, what)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work), intent(inout) :: work
      real(dp), intent(in) :: m(:, :), q(:), lo(:), hi(:)
      real(dp), intent(out) :: z(:, :), w(:, :)  !! (n, 4): lemke, enumeration, pgs, solve
      character(len=*), intent(in) :: what
      type(lcp_info) :: info
      integer :: k
      character(len=12), parameter :: names(4) = [character(len=12) :: 'lemke', 'enumeration', 'pgs', 'solve']

      do k = 1, 4
         select case (k)
         case (1)
            call box_lcp_lemke(work, m, q, lo, hi, z(:, k), w(:, k), info)
         case (2)
            call box_lcp_enumerate(work, m, q, lo, hi, z(:, k), w(:, k), info)
         case (3)
            z(:, k) = 0.0_dp
            call box_lcp_pgs(work, m, q, lo, hi, z(:, k), w(:, k), info)
         case (4)
            call box_lcp_solve(work, m, q, lo, hi, z(:, k), w(:, k), info)
         end select
         call check_status(error, info, lcp_solved, trim(what)//' '//trim(names(k)))
         if (allocated(error)) return
         call check_box(error, m, q, lo, hi, z(:, k), w(:, k), trim(what)//' '//trim(names(k)))
         if (allocated(error)) return
         call check(error, info%residual == box_lcp_residual(m, q, lo, hi, z(:, k), w(:, k)), &
                    trim(what)//' '//trim(names(k))//': reported residual is not that of z')
         if (allocated(error)) return
      end do
   end subroutine box_all

   !> A mass m on the ground held by two friction devices in parallel (limits c1, c2)
   !> under a force p: Delassus (1/m) [[1, 1], [1, 1]] (singular). The split of the forces
   !> is not unique; F1 + F2 = clamp(p, -c1 - c2, c1 + c2) and the acceleration
   !> s'' = -w = (p - F1 - F2)/m are.
   subroutine test_box_parallel(error)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work) :: work
      real(dp), parameter :: mass = 2.0_dp
      real(dp), parameter :: loads(10) = [-10.0_dp, -8.0_dp, -3.0_dp, 0.0_dp, 2.5_dp, 7.9_dp, 8.0_dp, &
                                          8.1_dp, 12.0_dp, 1.0e3_dp]
      real(dp) :: m(2, 2), lims(2, 2), c(2), z(2, 4), w(2, 4), ftot, wx
      integer :: il, ic, k
      character(len=96) :: what

      call new_work(error, work, 2, 2)
      if (allocated(error)) return
      work%pgs_tol = 1.0e-14_dp
      m = 1.0_dp/mass
      lims(:, 1) = [3.0_dp, 5.0_dp]   ! different limits
      lims(:, 2) = [4.0_dp, 4.0_dp]   ! identical devices
      do ic = 1, 2
         c = lims(:, ic)
         do il = 1, size(loads)
            what = 'parallel c = '//trim(fmt_real(c(1)))//', '//trim(fmt_real(c(2)))//' p = '// &
                   trim(fmt_real(loads(il)))
            call box_all(error, work, m, -loads(il)/mass*[1.0_dp, 1.0_dp], -c, c, z, w, trim(what))
            if (allocated(error)) return
            ftot = min(max(loads(il), -sum(c)), sum(c))
            wx = (ftot - loads(il))/mass
            do k = 1, 4
               call check_near(error, [z(1, k) + z(2, k)], [ftot], 1.0e-13_dp, trim(what)//' F1 + F2')
               if (allocated(error)) return
               call check_near(error, w(:, k), [wx, wx], 1.0e-13_dp, trim(what)//' w (unique)')
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_box_parallel

   !> A block of mass m on a table accelerating at ag, spring k stretched s0, one device of
   !> limit P mu: the force needed to stick is F = -m ag - k s0; the block sticks iff
   !> |F| <= P mu, else slides with F = P mu sgn F and s'' = (F_req - F)/m.
   subroutine test_box_table(error)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work) :: work
      real(dp), parameter :: mass = 1.5_dp, k = 200.0_dp, s0 = 0.01_dp, pmu = 0.3_dp*1.5_dp*9.81_dp
      real(dp) :: m(1, 1), z(1, 4), w(1, 4), ag, freq, fx
      integer :: i, j
      integer :: sticks, slides
      character(len=96) :: what

      call new_work(error, work, 1, 1)
      if (allocated(error)) return
      work%pgs_tol = 1.0e-14_dp
      m = 1.0_dp/mass
      sticks = 0
      slides = 0
      do i = -60, 60
         ag = 0.1_dp*i
         freq = -mass*ag - k*s0
         what = 'table ag = '//trim(fmt_real(ag))
         call box_all(error, work, m, [-freq/mass], [-pmu], [pmu], z, w, trim(what))
         if (allocated(error)) return
         fx = min(max(freq, -pmu), pmu)
         if (abs(freq) <= pmu) then
            sticks = sticks + 1
         else
            slides = slides + 1
         end if
         do j = 1, 4
            call check_near(error, z(:, j), [fx], 1.0e-14_dp, trim(what)//' F')
            if (allocated(error)) return
            call check_near(error, -w(:, j), [(freq - fx)/mass], 1.0e-14_dp, trim(what)//' s''''')
            if (allocated(error)) return
         end do
      end do
      call check(error, sticks > 10 .and. slides > 10, 'table: both phases met')
   end subroutine test_box_table

   !> Five masses in a chain, device d between mass d and mass d - 1 (d = 1: the ground),
   !> random masses, limits and loads: the box LCP (Delassus B'M^-1 B) against a search of
   !> all 3^5 stick / slide + / slide - patterns done on the mechanics directly.
   subroutine test_box_chain(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 5
      type(lcp_work) :: work
      type(rng_type) :: rng
      real(dp) :: mass(n), p(n), pmu(n), b(n, n), del(n, n), q(n), z(n, 4), w(n, 4)
      real(dp) :: fbf(n), sbf(n)
      integer :: kase, d, j, nvalid, npat(3)
      character(len=96) :: what

      call new_work(error, work, n, n)
      if (allocated(error)) return
      work%pgs_tol = 1.0e-14_dp
      work%pgs_max_sweeps = 100000
      b = 0.0_dp
      do d = 1, n
         b(d, d) = 1.0_dp
      end do
      do d = 2, n
         b(d - 1, d) = -1.0_dp
      end do
      npat = 0
      do kase = 1, 300
         call seed(rng, 40000 + kase)
         do d = 1, n
            mass(d) = uniform(rng, 0.5_dp, 2.0_dp)
            p(d) = uniform(rng, -10.0_dp, 10.0_dp)
            pmu(d) = uniform(rng, 0.5_dp, 6.0_dp)
         end do
         ! Delassus B' M^-1 B and q = -B' M^-1 p
         do j = 1, n
            do d = 1, n
               del(d, j) = sum(b(:, d)*b(:, j)/mass)
            end do
            q(j) = -sum(b(:, j)*p/mass)
         end do
         call brute_force_chain(mass, p, pmu, b, fbf, sbf, nvalid, npat)
         what = 'chain case '//trim(fmt_int(kase))
         call check(error, nvalid == 1, trim(what)//': '//trim(fmt_int(nvalid))//' valid patterns')
         if (allocated(error)) return
         call box_all(error, work, del, q, -pmu, pmu, z, w, trim(what))
         if (allocated(error)) return
         do j = 1, 4
            call check_near(error, z(:, j), fbf, atol, trim(what)//' forces')
            if (allocated(error)) return
            call check_near(error, -w(:, j), sbf, atol, trim(what)//' relative accelerations')
            if (allocated(error)) return
         end do
      end do
      call check(error, all(npat > 100), 'chain: sticking '//trim(fmt_int(npat(1)))//', sliding + '// &
                 trim(fmt_int(npat(2)))//', sliding - '//trim(fmt_int(npat(3)))//' device-cases')
   end subroutine test_box_chain

   !> Every pattern of the chain: sliding devices carry +-P mu, sticking ones the forces that
   !> keep s'' = 0 (LAPACK LU); valid when |F| <= P mu and every slider accelerates its way.
   subroutine brute_force_chain(mass, p, pmu, b, fv, sv, nvalid, npat)
      real(dp), intent(in) :: mass(:), p(:), pmu(:), b(:, :)
      real(dp), intent(out) :: fv(:), sv(:)
      integer, intent(out) :: nvalid
      integer, intent(inout) :: npat(3)
      integer :: n, code, d, k, info, ph(size(p))
      integer, allocatable :: st(:), ipiv(:)
      real(dp) :: f(size(p)), acc(size(p)), s(size(p)), r(size(p)), tol
      real(dp), allocatable :: a(:, :), rhs(:, :)
      logical :: ok

      n = size(p)
      nvalid = 0
      tol = 1.0e-12_dp*maxval(abs(p))
      do code = 0, 3**n - 1
         k = code
         do d = 1, n
            ph(d) = mod(k, 3) - 1        ! -1 slide -, 0 stick, +1 slide +
            k = k/3
         end do
         f = real(ph, dp)*pmu
         st = pack([(d, d=1, n)], ph == 0)
         if (size(st) > 0) then
            ! B_S' M^-1 B_S F_S = B_S' M^-1 (p - B_L F_L)
            r = p - matmul(b, f)
            a = matmul(transpose(b(:, st)), b(:, st)/spread(mass, 2, size(st)))
            rhs = reshape(matmul(transpose(b(:, st)), r/mass), [size(st), 1])
            allocate (ipiv(size(st)))
            call lu_solve(a, rhs, ipiv, info)
            deallocate (ipiv)
            if (info /= 0) cycle
            f(st) = rhs(:, 1)
         end if
         acc = (p - matmul(b, f))/mass
         s = matmul(transpose(b), acc)
         ok = .true.
         do d = 1, n
            select case (ph(d))
            case (0)
               ok = ok .and. abs(f(d)) <= pmu(d)*(1.0_dp + 1.0e-12_dp) .and. abs(s(d)) <= tol
            case (1)
               ok = ok .and. s(d) >= -tol
            case (-1)
               ok = ok .and. s(d) <= tol
            end select
         end do
         if (ok) then
            nvalid = nvalid + 1
            fv = f
            sv = s
            do d = 1, n
               select case (ph(d))
               case (0)
                  npat(1) = npat(1) + 1
               case (1)
                  npat(2) = npat(2) + 1
               case default
                  npat(3) = npat(3) + 1
               end select
            end do
         end if
      end do
   end subroutine brute_force_chain

   !> Random box problems: symmetric positive definite (z unique) and singular positive
   !> semidefinite (w unique), some variables fixed (lo = hi): all methods agree.
   subroutine test_box_random(error)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work) :: work
      type(rng_type) :: rng
      real(dp), allocatable :: m(:, :), q(:), lo(:), hi(:), z(:, :), w(:, :)
      integer :: n, k, i, j, kind
      character(len=96) :: what

      call new_work(error, work, 6, 6)
      if (allocated(error)) return
      work%pgs_tol = 1.0e-14_dp
      work%pgs_max_sweeps = 200000
      do n = 1, 6
         allocate (m(n, n), q(n), lo(n), hi(n), z(n, 4), w(n, 4))
         do kind = 1, 2
            do k = 1, 60
               call seed(rng, 60000 + 1000*n + 100*kind + k)
               if (kind == 1) then
                  call random_gram(rng, n, n, 0.5_dp, m)
               else
                  call random_gram(rng, n, max(1, n/2), 0.0_dp, m)   ! rank n/2
               end if
               do i = 1, n
                  q(i) = uniform(rng, -2.0_dp, 2.0_dp)
                  lo(i) = -uniform(rng, 0.0_dp, 1.0_dp)
                  hi(i) = uniform(rng, 0.0_dp, 1.0_dp)
               end do
               if (mod(k, 7) == 0) hi(1) = lo(1)
               what = 'box '//trim(merge('SPD', 'PSD', kind == 1))//' n = '//trim(fmt_int(n))// &
                      ' seed '//trim(fmt_int(k))
               call box_all(error, work, m, q, lo, hi, z, w, trim(what))
               if (allocated(error)) return
               do j = 2, 4
                  call check_near(error, w(:, j), w(:, 1), atol, trim(what)//' w')
                  if (allocated(error)) return
                  if (kind == 1) then
                     call check_near(error, z(:, j), z(:, 1), atol, trim(what)//' z')
                     if (allocated(error)) return
                  end if
               end do
            end do
         end do
         deallocate (m, q, lo, hi, z, w)
      end do
   end subroutine test_box_random

   !> A box LCP has a solution for every M (Hartman-Stampacchia): box_lcp_solve finds one for
   !> random general matrices (Lemke, or enumeration where Lemke ends on a ray).
   subroutine test_box_general(error)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work) :: work
      type(rng_type) :: rng
      real(dp), allocatable :: m(:, :), q(:), lo(:), hi(:), z(:), w(:)
      type(lcp_info) :: info
      integer :: n, k, i, j
      character(len=96) :: what

      call new_work(error, work, 5, 5)
      if (allocated(error)) return
      work%tol = ctol
      do n = 1, 5
         allocate (m(n, n), q(n), lo(n), hi(n), z(n), w(n))
         do k = 1, 200
            call seed(rng, 80000 + 1000*n + k)
            do j = 1, n
               do i = 1, n
                  m(i, j) = uniform(rng, -1.0_dp, 1.0_dp)
               end do
               q(j) = uniform(rng, -1.0_dp, 1.0_dp)
               lo(j) = -uniform(rng, 0.0_dp, 1.0_dp)
               hi(j) = uniform(rng, 0.0_dp, 1.0_dp)
            end do
            what = 'box general n = '//trim(fmt_int(n))//' seed '//trim(fmt_int(k))
            call box_lcp_solve(work, m, q, lo, hi, z, w, info)
            call check_status(error, info, lcp_solved, trim(what))
            if (allocated(error)) return
            call check_box(error, m, q, lo, hi, z, w, trim(what))
            if (allocated(error)) return
         end do
         deallocate (m, q, lo, hi, z, w)
      end do
   end subroutine test_box_general

   !> A box LCP whose q is subnormal (a record of 2e-309 m/s^2 under a block of limits
   !> +-1): the solution is z = -q/M inside the box, zero to round-off at the bounds' scale,
   !> and is solved; the residual is measured at the scale of the bounds (scaled by zs/ws it
   !> would overflow, and the answer z = 0 count as a residual of 1, "not solved").
   subroutine test_box_subnormal(error)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_work) :: work
      type(lcp_info) :: info
      real(dp) :: m(1, 1), q(1), z(1), w(1)

      call new_work(error, work, 1, 1)
      if (allocated(error)) return
      m = 2.0_dp
      q = 2.2250738585072014e-309_dp
      call box_lcp_solve(work, m, q, [-1.0_dp], [1.0_dp], z, w, info)
      call check(error, info%status == lcp_solved, 'subnormal q: solved')
      if (allocated(error)) return
      call check(error, abs(z(1)) <= 2.0e-309_dp .and. info%residual <= 1.0e-15_dp, &
                 'subnormal q: z within |q| of zero, residual at round-off')
   end subroutine test_box_subnormal

end module test_fd_lcp
