!> Unit tests of the structure-aware effective stiffness (fd_banded, fd_rcm): the banded and
!> dense paths against an independent dense assembly factored by LAPACK's dpotrf, every
!> pattern of sticking devices reached by rank-one updates, long random sequences of
!> updates and downdates, the fallback when a downdate loses its pivot, the partial
!> refactorization, the RCM ordering and the matrix-vector products.
module test_fd_banded
   use, intrinsic :: iso_fortran_env, only: int64
   use testdrive, only: new_unittest, unittest_type, error_type, check, test_failed
   use fd_kinds, only: dp
   use fd_error, only: lib_error => error_type
   use fd_linalg, only: cholesky_factor, cholesky_solve, sym_matvec
   use fd_rcm, only: rcm_order, graph_bandwidth
   use fd_kinematics, only: pair_terms
   use fd_banded, only: spd_system, spd_setup, spd_factor, spd_update_device, spd_update_devices, &
                        spd_solve, spd_k_matvec, spd_c_matvec, spd_bandwidth, spd_is_dense, &
                        spd_error_estimate, spd_auto, spd_dense, spd_banded, spd_dense_max_n, &
                        spd_choose, spd_rank_one, spd_refactor, band_potf2, spd_kc_matvec
   implicit none
   private

   public :: collect_banded

   !> A structure as lists: masses, springs, devices, dashpots, Rayleigh coefficients.
   type :: problem
      integer :: n = 0
      real(dp), allocatable :: mass(:), sk(:), pc(:)
      integer, allocatable :: si(:), sj(:), di(:), dj(:), pi(:), pj(:)
      real(dp) :: a0 = 0.0_dp, a1 = 0.0_dp
   end type problem

   real(dp), parameter :: h = 0.01_dp                   !! step of the Newmark coefficients
   real(dp), parameter :: c0 = 4.0_dp/h**2, c1 = 2.0_dp/h !! average acceleration

contains

   subroutine collect_banded(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("rcm chain bandwidth 1", test_rcm_chain), &
                  new_unittest("rcm frame band", test_rcm_frame), &
                  new_unittest("rcm order equals the reference", test_rcm_reference), &
                  new_unittest("rcm linear in nodes + edges", test_rcm_linear), &
                  new_unittest("banded solve equals dense", test_solve), &
                  new_unittest("matvecs equal dense", test_matvec), &
                  new_unittest("every device pattern n=10", test_patterns), &
                  new_unittest("long random update sequence", test_long_sequence), &
                  new_unittest("fallback on lost pivot", test_fallback), &
                  new_unittest("partial refactorization", test_partial), &
                  new_unittest("update local when inertia dominates", test_local_update), &
                  new_unittest("storage chosen by size", test_auto_path), &
                  new_unittest("bad input named", test_errors), &
                  new_unittest("narrow band factor is dpbtf2's", test_band_potf2), &
                  new_unittest("small K^ products in dsymv's order", test_small_kc), &
                  new_unittest("devices along general directions", test_general_devices) &
                  ]
   end subroutine collect_banded

   ! ---------------------------------------------------------------- structures

   subroutine seed(k)
      integer, intent(in) :: k
      integer :: m, i
      integer, allocatable :: s(:)

      call random_seed(size=m)
      allocate (s(m))
      s = 7919*k + [(104729*i, i=1, size(s))]
      call random_seed(put=s)
   end subroutine seed

   real(dp) function urand(lo, hi)
      real(dp), intent(in) :: lo, hi
      real(dp) :: r

      call random_number(r)
      urand = lo + (hi - lo)*r
   end function urand

   !> A random permutation of 1..n (identity when not shuffled).
   subroutine shuffle(n, q, mix)
      integer, intent(in) :: n
      integer, allocatable, intent(out) :: q(:)
      logical, intent(in) :: mix
      integer :: i, j, t

      q = [(i, i=1, n)]
      if (.not. mix) return
      do i = n, 2, -1
         j = 1 + int(urand(0.0_dp, real(i, dp)))
         j = min(j, i)
         t = q(i); q(i) = q(j); q(j) = t
      end do
   end subroutine shuffle

   !> Shear building of n storeys, randomly numbered: a spring and a friction device in every
   !> storey (the first to the table), dashpots in every third storey, Rayleigh damping.
   subroutine chain(n, pb, mix)
      integer, intent(in) :: n
      type(problem), intent(out) :: pb
      logical, intent(in) :: mix
      integer, allocatable :: q(:)
      integer :: k, below

      call shuffle(n, q, mix)
      pb%n = n
      allocate (pb%mass(n), pb%sk(n), pb%si(n), pb%sj(n), pb%di(n), pb%dj(n))
      allocate (pb%pi(0), pb%pj(0), pb%pc(0))
      do k = 1, n
         below = 0
         if (k > 1) below = q(k - 1)
         pb%mass(q(k)) = urand(1.0_dp, 2.0_dp)
         pb%si(k) = q(k); pb%sj(k) = below; pb%sk(k) = urand(1.0e3_dp, 2.0e3_dp)
         pb%di(k) = below; pb%dj(k) = q(k)
         if (mod(k, 3) == 0) then
            pb%pi = [pb%pi, q(k)]
            pb%pj = [pb%pj, below]
            pb%pc = [pb%pc, urand(1.0_dp, 5.0_dp)]
         end if
      end do
      pb%a0 = 0.3_dp
      pb%a1 = 2.0e-3_dp
   end subroutine chain

   !> Plane frame of nx columns and ny floors, randomly numbered: column springs (the first
   !> floor to the table), beam springs, a friction brace along the diagonal of every bay and
   !> a friction device in the first column of every storey.
   subroutine frame(nx, ny, pb, mix)
      integer, intent(in) :: nx, ny
      type(problem), intent(out) :: pb
      logical, intent(in) :: mix
      integer, allocatable :: q(:)
      integer :: c, f, below

      pb%n = nx*ny
      call shuffle(pb%n, q, mix)
      allocate (pb%mass(pb%n), pb%sk(0), pb%si(0), pb%sj(0), pb%di(0), pb%dj(0))
      allocate (pb%pi(0), pb%pj(0), pb%pc(0))
      do f = 1, ny
         do c = 1, nx
            pb%mass(node(c, f)) = urand(1.0_dp, 2.0_dp)
            below = 0
            if (f > 1) below = node(c, f - 1)
            pb%si = [pb%si, node(c, f)]; pb%sj = [pb%sj, below]; pb%sk = [pb%sk, urand(1.0e3_dp, 2.0e3_dp)]
            if (c == 1) then
               pb%di = [pb%di, node(c, f)]; pb%dj = [pb%dj, below]
            end if
            if (c < nx) then
               pb%si = [pb%si, node(c, f)]; pb%sj = [pb%sj, node(c + 1, f)]
               pb%sk = [pb%sk, urand(1.0e3_dp, 2.0e3_dp)]
               below = 0
               if (f > 1) below = node(c + 1, f - 1)
               pb%di = [pb%di, node(c, f)]; pb%dj = [pb%dj, below]
               if (mod(c + f, 2) == 0) then
                  pb%pi = [pb%pi, node(c, f)]; pb%pj = [pb%pj, node(c + 1, f)]; pb%pc = [pb%pc, 3.0_dp]
               end if
            end if
         end do
      end do
      pb%a0 = 0.2_dp
      pb%a1 = 1.0e-3_dp
   contains
      integer function node(cc, ff)
         integer, intent(in) :: cc, ff
         node = q((ff - 1)*nx + cc)
      end function node
   end subroutine frame

   !> Two chains side by side, not connected: two components of the graph.
   subroutine two_chains(n1, n2, pb)
      integer, intent(in) :: n1, n2
      type(problem), intent(out) :: pb
      type(problem) :: a, b

      call chain(n1, a, .true.)
      call chain(n2, b, .true.)
      pb%n = n1 + n2
      pb%mass = [a%mass, b%mass]
      pb%si = [a%si, shift(b%si)]; pb%sj = [a%sj, shift(b%sj)]; pb%sk = [a%sk, b%sk]
      pb%di = [a%di, shift(b%di)]; pb%dj = [a%dj, shift(b%dj)]
      pb%pi = [a%pi, shift(b%pi)]; pb%pj = [a%pj, shift(b%pj)]; pb%pc = [a%pc, b%pc]
      pb%a0 = a%a0
      pb%a1 = a%a1
   contains
      function shift(v) result(w)
         integer, intent(in) :: v(:)
         integer :: w(size(v))
         w = merge(v + n1, 0, v > 0)
      end function shift
   end subroutine two_chains

   subroutine setup(pb, sys, path, method, budget, error)
      type(problem), intent(in) :: pb
      type(spd_system), intent(out) :: sys
      integer, intent(in) :: path, method
      real(dp), intent(in), optional :: budget
      type(error_type), allocatable, intent(out) :: error
      type(lib_error), allocatable :: err

      call pair_setup(sys, pb%mass, pb%si, pb%sj, pb%sk, pb%di, pb%dj, err, a0=pb%a0, a1=pb%a1, &
                     dashpot_i=pb%pi, dashpot_j=pb%pj, dashpot_c=pb%pc, path=path, method=method, &
                     budget=budget)
      call pass(err, error)
   end subroutine setup

   subroutine pass(err, error)
      type(lib_error), allocatable, intent(in) :: err
      type(error_type), allocatable, intent(out) :: error

      if (allocated(err)) call test_failed(error, "library error: "//err%message)
   end subroutine pass

   ! ------------------------------------------------------- dense reference

   subroutine add_link(a, i, j, k)
      real(dp), intent(inout) :: a(:, :)
      integer, intent(in) :: i, j
      real(dp), intent(in) :: k

      if (i > 0) a(i, i) = a(i, i) + k
      if (j > 0) a(j, j) = a(j, j) + k
      if (i > 0 .and. j > 0) then
         a(i, j) = a(i, j) - k
         a(j, i) = a(j, i) - k
      end if
   end subroutine add_link

   subroutine dense_k(pb, a)
      type(problem), intent(in) :: pb
      real(dp), allocatable, intent(out) :: a(:, :)
      integer :: e

      allocate (a(pb%n, pb%n))
      a = 0.0_dp
      do e = 1, size(pb%si)
         call add_link(a, pb%si(e), pb%sj(e), pb%sk(e))
      end do
   end subroutine dense_k

   subroutine dense_c(pb, a)
      type(problem), intent(in) :: pb
      real(dp), allocatable, intent(out) :: a(:, :)
      integer :: e, i

      call dense_k(pb, a)
      a = pb%a1*a
      do i = 1, pb%n
         a(i, i) = a(i, i) + pb%a0*pb%mass(i)
      end do
      do e = 1, size(pb%pi)
         call add_link(a, pb%pi(e), pb%pj(e), pb%pc(e))
      end do
   end subroutine dense_c

   !> x = (K + c1 C + c0 M + sum kd b b')^-1 b by an independent dense assembly and dpotrf.
   subroutine dense_solve(pb, kd, b, x)
      type(problem), intent(in) :: pb
      real(dp), intent(in) :: kd(:), b(:)
      real(dp), allocatable, intent(out) :: x(:)
      real(dp), allocatable :: a(:, :), c(:, :)
      integer :: i, d, info

      call dense_k(pb, a)
      call dense_c(pb, c)
      a = a + c1*c
      do i = 1, pb%n
         a(i, i) = a(i, i) + c0*pb%mass(i)
      end do
      do d = 1, size(pb%di)
         call add_link(a, pb%di(d), pb%dj(d), kd(d))
      end do
      call cholesky_factor(a, info)
      x = b
      call cholesky_solve(a, x)
   end subroutine dense_solve

   real(dp) function rel_diff(x, y)
      real(dp), intent(in) :: x(:), y(:)

      rel_diff = norm2(x - y)/norm2(y)
   end function rel_diff

   !> Solve with sys and with a fresh dense factor; their relative difference.
   subroutine compare(pb, sys, kd, b, diff, error)
      type(problem), intent(in) :: pb
      type(spd_system), intent(inout) :: sys
      real(dp), intent(in) :: kd(:), b(:)
      real(dp), intent(out) :: diff
      type(error_type), allocatable, intent(out) :: error
      type(lib_error), allocatable :: err
      real(dp), allocatable :: x(:), xref(:)

      allocate (x(size(b)))
      x(:) = b
      call spd_solve(sys, x, err)
      call pass(err, error)
      if (allocated(error)) return
      call dense_solve(pb, kd, b, xref)
      diff = rel_diff(x, xref)
   end subroutine compare

   subroutine random_vector(n, b)
      integer, intent(in) :: n
      real(dp), allocatable, intent(out) :: b(:)
      integer :: i

      allocate (b(n))
      do i = 1, n
         b(i) = urand(-1.0_dp, 1.0_dp)
      end do
   end subroutine random_vector

   !> A device stiffness of a sticking device: up to 25 times the inertia term c0 m.
   real(dp) function stick_kd()
      stick_kd = urand(1.0e4_dp, 1.0e6_dp)
   end function stick_kd

   ! ------------------------------------------------------------------ tests

   !> A chain numbered at random comes back as a path; a two-component graph too.
   subroutine test_rcm_chain(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem) :: pb
      type(spd_system) :: sys
      integer, allocatable :: perm(:), inv(:), ei(:), ej(:)
      integer :: i, trial, n

      call seed(1)
      do trial = 1, 5
         n = 10*trial**2
         call chain(n, pb, .true.)
         ei = [pb%si, pb%di]
         ej = [pb%sj, pb%dj]
         allocate (perm(n), inv(n))
         call rcm_order(n, ei, ej, perm)
         inv = 0
         inv(perm) = [(i, i=1, n)]
         call check(error, all(inv > 0), "rcm_order does not return a permutation")
         if (allocated(error)) return
         call check(error, graph_bandwidth(ei, ej, [(i, i=1, n)]) > n/4, &
                    "the random numbering should have a wide band")
         if (allocated(error)) return
         call check(error, graph_bandwidth(ei, ej, inv), 1)
         if (allocated(error)) return
         deallocate (perm, inv)
      end do
      call setup(pb, sys, spd_banded, spd_choose, error=error)
      if (allocated(error)) return
      call check(error, spd_bandwidth(sys), 1)
      if (allocated(error)) return
      call two_chains(30, 45, pb)
      call setup(pb, sys, spd_banded, spd_choose, error=error)
      if (allocated(error)) return
      call check(error, spd_bandwidth(sys), 1)
   end subroutine test_rcm_chain

   !> A randomly numbered frame of nx columns gets a band of the order of nx: at most the
   !> two widest consecutive level sets of the breadth-first search from a corner.
   subroutine test_rcm_frame(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem) :: pb
      type(spd_system) :: sys
      integer :: nx

      call seed(2)
      do nx = 2, 6
         call frame(nx, 40, pb, .true.)
         call setup(pb, sys, spd_banded, spd_choose, error=error)
         if (allocated(error)) return
         call check(error, spd_bandwidth(sys) >= nx .and. spd_bandwidth(sys) <= 2*nx, &
                    "frame with columns and braces: band outside nx..2 nx")
         if (allocated(error)) return
      end do
   end subroutine test_rcm_frame

   !> Banded (RCM) and dense factors solve like an independent dense assembly, to 1e-12.
   subroutine test_solve(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem) :: pb
      type(spd_system) :: sys
      type(lib_error), allocatable :: err
      real(dp), allocatable :: kd(:), b(:)
      real(dp) :: diff, worst
      integer :: trial, d, path

      call seed(3)
      worst = 0.0_dp
      do trial = 1, 12
         select case (mod(trial, 4))
         case (0)
            call chain(1 + 7*trial**2, pb, .true.)
         case (1)
            call frame(1 + mod(trial, 5), 3*trial, pb, .true.)
         case (2)
            call two_chains(trial, 3*trial, pb)
         case default
            call chain(trial, pb, .true.)
         end select
         allocate (kd(size(pb%di)))
         do d = 1, size(kd)
            kd(d) = merge(stick_kd(), 0.0_dp, urand(0.0_dp, 1.0_dp) < 0.5_dp)
         end do
         call random_vector(pb%n, b)
         do path = spd_dense, spd_banded
            call setup(pb, sys, path, spd_choose, error=error)
            if (allocated(error)) return
            call spd_factor(sys, c0, c1, kd, err)
            call pass(err, error)
            if (allocated(error)) return
            call compare(pb, sys, kd, b, diff, error)
            if (allocated(error)) return
            worst = max(worst, diff)
            call check(error, diff <= 1.0e-12_dp, "n = "//trim(itoa(pb%n))//": solve differs from dense by "// &
                       trim(rtoa(diff)))
            if (allocated(error)) return
         end do
         deallocate (kd)
      end do
   end subroutine test_solve

   !> K x and C x (alpha, beta) equal the dense products, banded and dense storage.
   subroutine test_matvec(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem) :: pb
      type(spd_system) :: sys
      real(dp), allocatable :: kk(:, :), cc(:, :), x(:), y(:), y0(:), yref(:)
      integer :: path, trial

      call seed(4)
      do trial = 1, 3
         if (trial == 1) call chain(40, pb, .true.)
         if (trial == 2) call frame(4, 9, pb, .true.)
         if (trial == 3) call two_chains(5, 9, pb)
         call dense_k(pb, kk)
         call dense_c(pb, cc)
         call random_vector(pb%n, x)
         call random_vector(pb%n, y0)
         do path = spd_dense, spd_banded
            call setup(pb, sys, path, spd_choose, error=error)
            if (allocated(error)) return
            y = y0
            call spd_k_matvec(sys, x, y, -0.7_dp, 2.0_dp)
            yref = -0.7_dp*matmul(kk, x) + 2.0_dp*y0
            call check(error, rel_diff(y, yref) <= 1.0e-14_dp, "K x differs: "//trim(rtoa(rel_diff(y, yref))))
            if (allocated(error)) return
            y = huge(1.0_dp)
            call spd_c_matvec(sys, x, y, 1.5_dp, 0.0_dp)
            yref = 1.5_dp*matmul(cc, x)
            call check(error, rel_diff(y, yref) <= 1.0e-14_dp, "C x differs: "//trim(rtoa(rel_diff(y, yref))))
            if (allocated(error)) return
            ! the library's dense product agrees too (same upper triangle convention)
            y = 0.0_dp
            call sym_matvec(kk, x, y, 1.0_dp, 0.0_dp)
            yref = y
            call spd_k_matvec(sys, x, y, 1.0_dp, 0.0_dp)
            call check(error, rel_diff(y, yref) <= 1.0e-14_dp, "K x differs from dsymv")
            if (allocated(error)) return
         end do
      end do
   end subroutine test_matvec

   !> A 10-storey building with a device in every storey (the first to the table): all 2^10
   !> patterns of sticking devices, reached one device at a time in Gray-code order by
   !> rank-one updates and downdates, solve like a fresh dense factor to 1e-10.
   subroutine test_patterns(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem) :: pb
      type(spd_system) :: sys
      type(lib_error), allocatable :: err
      real(dp), allocatable :: kon(:), kd(:), b(:)
      real(dp) :: diff, worst
      integer :: variant, t, d, path, method, ndev

      call seed(5)
      do variant = 1, 5
         if (variant <= 4) then
            call chain(10, pb, .true.)
         else
            call frame(2, 5, pb, .true.)  ! 10 DOFs, 10 devices: 2^10 patterns on a band of 2..4
         end if
         ndev = size(pb%di)
         path = merge(spd_dense, spd_banded, variant == 3)
         method = spd_rank_one
         if (variant == 2) method = spd_choose
         if (variant == 4) method = spd_refactor
         allocate (kon(ndev))
         do d = 1, ndev
            kon(d) = stick_kd()
         end do
         allocate (kd(ndev))
         kd = 0.0_dp
         call random_vector(pb%n, b)
         call setup(pb, sys, path, method, error=error)
         if (allocated(error)) return
         call spd_factor(sys, c0, c1, kd, err)
         call pass(err, error)
         if (allocated(error)) return
         worst = 0.0_dp
         do t = 1, 2**ndev - 1
            d = 1 + trailz(t)
            kd(d) = merge(0.0_dp, kon(d), kd(d) > 0.0_dp)
            call spd_update_device(sys, d, kd(d), err)
            call pass(err, error)
            if (allocated(error)) return
            call compare(pb, sys, kd, b, diff, error)
            if (allocated(error)) return
            worst = max(worst, diff)
         end do
         call check(error, worst <= 1.0e-10_dp, "variant "//trim(itoa(variant))//": a pattern differs from "// &
                    "the dense factor by "//trim(rtoa(worst)))
         if (allocated(error)) return
         associate (s => sys%stats)
            call check(error, s%updates + s%downdates + s%partial + s%fallbacks + s%refreshes, 2**ndev - 1)
            if (allocated(error)) return
            if (method == spd_rank_one) then
               ! the rank-one path did the work (refactorizations only when the budget says so)
               call check(error, s%updates >= 400 .and. s%downdates >= 400, "variant "//trim(itoa(variant))// &
                          ": too few rank-one modifications: "//trim(itoa(s%updates))//" updates, "// &
                          trim(itoa(s%downdates))//" downdates")
               if (allocated(error)) return
            end if
            if (method == spd_refactor) then
               call check(error, s%partial, 2**ndev - 1)
               if (allocated(error)) return
            end if
         end associate
         deallocate (kon, kd)
      end do
   end subroutine test_patterns

   !> 20000 random changes of 1 to 3 devices of a braced frame (stiffness up or down, or a
   !> device released): every 100 changes the factor still solves like a fresh one (1e-10),
   !> and its error estimate stays within the budget.
   subroutine test_long_sequence(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem) :: pb
      type(spd_system) :: sys
      type(lib_error), allocatable :: err
      real(dp), allocatable :: kd(:), b(:)
      real(dp) :: diff, worst
      integer :: t, j, d, ndev

      call seed(6)
      call frame(4, 15, pb, .true.)
      ndev = size(pb%di)
      allocate (kd(ndev))
      do d = 1, ndev
         kd(d) = stick_kd()
      end do
      call random_vector(pb%n, b)
      call setup(pb, sys, spd_banded, spd_rank_one, error=error)
      if (allocated(error)) return
      call spd_factor(sys, c0, c1, kd, err)
      call pass(err, error)
      if (allocated(error)) return
      worst = 0.0_dp
      do t = 1, 20000
         do j = 1, 1 + int(urand(0.0_dp, 2.999_dp))
            d = 1 + min(ndev - 1, int(urand(0.0_dp, real(ndev, dp))))
            if (urand(0.0_dp, 1.0_dp) < 0.3_dp) then
               kd(d) = 0.0_dp
            else
               kd(d) = stick_kd()
            end if
         end do
         call spd_update_devices(sys, kd, err)
         call pass(err, error)
         if (allocated(error)) return
         if (mod(t, 100) == 0) then
            call compare(pb, sys, kd, b, diff, error)
            if (allocated(error)) return
            worst = max(worst, diff)
            call check(error, spd_error_estimate(sys) <= 1.0e-12_dp, "error estimate over the budget")
            if (allocated(error)) return
         end if
      end do
      call check(error, worst <= 1.0e-10_dp, "after a long sequence the factor differs from a fresh one by "// &
                 trim(rtoa(worst)))
      if (allocated(error)) return
      call check(error, sys%stats%updates > 10000 .and. sys%stats%downdates > 10000, &
                 "the sequence should be made of rank-one modifications")
   end subroutine test_long_sequence

   !> A device far stiffer than the rest of its row, then released: the downdate loses the
   !> pivot (1e17: the diagonal was absorbed, positive definiteness is lost to round-off;
   !> 1e14: ten digits cancel). Both fall back to a refactorization and solve to 1e-12. With
   !> the check off (an unlimited budget) the 1e14 downdate goes through and is visibly
   !> wrong (1e-8 and worse): the fallback is what keeps the answer right.
   subroutine test_fallback(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem) :: pb
      type(spd_system) :: sys
      type(lib_error), allocatable :: err
      real(dp), allocatable :: kd(:), b(:)
      real(dp) :: diff, big(2)
      integer :: i, path

      call seed(7)
      call chain(10, pb, .true.)
      allocate (kd(10))
      call random_vector(pb%n, b)
      big = [1.0e17_dp, 1.0e14_dp]
      do path = spd_dense, spd_banded
         do i = 1, 2
            call setup(pb, sys, path, spd_rank_one, error=error)
            if (allocated(error)) return
            kd = 0.0_dp
            call spd_factor(sys, c0, c1, kd, err)
            call pass(err, error)
            if (allocated(error)) return
            call spd_update_device(sys, 4, big(i), err)
            call pass(err, error)
            if (allocated(error)) return
            call spd_update_device(sys, 4, 0.0_dp, err)
            call pass(err, error)
            if (allocated(error)) return
            call check(error, sys%stats%fallbacks, 1)
            if (allocated(error)) return
            call check(error, sys%stats%downdates, 0)
            if (allocated(error)) return
            call compare(pb, sys, kd, b, diff, error)
            if (allocated(error)) return
            call check(error, diff <= 1.0e-12_dp, "after the fallback: "//trim(rtoa(diff)))
            if (allocated(error)) return
            call check(error, spd_error_estimate(sys) == 0.0_dp, "a fresh factor has no update error")
            if (allocated(error)) return
         end do
         ! the same 1e14 downdate without the accuracy check
         call setup(pb, sys, path, spd_rank_one, budget=1.0_dp, error=error)
         if (allocated(error)) return
         call spd_factor(sys, c0, c1, kd, err)
         call pass(err, error)
         if (allocated(error)) return
         call spd_update_device(sys, 4, big(2), err)
         call pass(err, error)
         if (allocated(error)) return
         call spd_update_device(sys, 4, 0.0_dp, err)
         call pass(err, error)
         if (allocated(error)) return
         call check(error, sys%stats%fallbacks == 0 .and. sys%stats%downdates == 1, &
                    "with an unlimited budget the downdate should go through")
         if (allocated(error)) return
         call compare(pb, sys, kd, b, diff, error)
         if (allocated(error)) return
         call check(error, diff > 1.0e-8_dp, "an unchecked 1e14 downdate should be inaccurate, differs by "// &
                    trim(rtoa(diff)))
         if (allocated(error)) return
      end do
   end subroutine test_fallback

   !> Several devices changed at once: the refactorization from the first changed column
   !> (rows above it kept) solves like a fresh factor, on band and dense storage; on a long
   !> chain, changes near the end of the ordering are made by refactoring the last columns.
   subroutine test_partial(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem) :: pb
      type(spd_system) :: sys
      type(lib_error), allocatable :: err
      real(dp), allocatable :: kd(:), b(:)
      real(dp) :: diff
      integer :: path, t, d, ndev, trial

      call seed(8)
      do trial = 1, 2
         if (trial == 1) call chain(200, pb, .true.)
         if (trial == 2) call frame(5, 30, pb, .true.)
         ndev = size(pb%di)
         allocate (kd(ndev))
         kd = 0.0_dp
         call random_vector(pb%n, b)
         do path = spd_dense, spd_banded
            call setup(pb, sys, path, spd_refactor, error=error)
            if (allocated(error)) return
            call spd_factor(sys, c0, c1, kd, err)
            call pass(err, error)
            if (allocated(error)) return
            do t = 1, 30
               do d = 1, 4
                  kd(1 + mod(7*t + 13*d, ndev)) = merge(0.0_dp, stick_kd(), mod(t + d, 3) == 0)
               end do
               call spd_update_devices(sys, kd, err)
               call pass(err, error)
               if (allocated(error)) return
               call compare(pb, sys, kd, b, diff, error)
               if (allocated(error)) return
               call check(error, diff <= 1.0e-12_dp, "partial refactorization differs by "//trim(rtoa(diff)))
               if (allocated(error)) return
            end do
            call check(error, sys%stats%partial, 30)
            if (allocated(error)) return
            call check(error, sys%stats%factorizations, 1)
            if (allocated(error)) return
         end do
         deallocate (kd)
      end do
   end subroutine test_partial

   !> In a 600-storey building at a Newmark step of 10 ms (c0 m is 30 times the storey
   !> stiffness) the change of the factor from a device in the middle storey decays by about
   !> that factor per storey: the update stops after a few storeys, and still solves like a
   !> fresh factor. Without inertia (a static solve of a chain tied to the table at both
   !> ends, so that no part of it floats) the change does not decay and the update runs to
   !> the end of the chain.
   subroutine test_local_update(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem) :: pb
      type(spd_system) :: sys
      type(lib_error), allocatable :: err
      real(dp), allocatable :: kd(:), b(:), x(:), xref(:), a(:, :)
      real(dp) :: diff
      integer :: trial, d, info
      integer(int64) :: cols
      integer, parameter :: n = 600, mid = 300

      call seed(11)
      call chain(n, pb, .false.)
      pb%si = [pb%si, n]
      pb%sj = [pb%sj, 0]
      pb%sk = [pb%sk, 1.0e3_dp]
      pb%a0 = 0.0_dp
      pb%a1 = 0.0_dp
      allocate (kd(n))
      kd = 0.0_dp
      call random_vector(n, b)
      call setup(pb, sys, spd_banded, spd_rank_one, error=error)
      if (allocated(error)) return
      call spd_factor(sys, c0, c1, kd, err)
      call pass(err, error)
      if (allocated(error)) return
      do trial = 1, 2
         kd(mid) = merge(stick_kd(), 0.0_dp, trial == 1)
         call spd_update_device(sys, mid, kd(mid), err)
         call pass(err, error)
         if (allocated(error)) return
         call compare(pb, sys, kd, b, diff, error)
         if (allocated(error)) return
         call check(error, diff <= 1.0e-12_dp, "local update differs from dense by "//trim(rtoa(diff)))
         if (allocated(error)) return
      end do
      call check(error, sys%stats%update_columns <= 2*10, "an update at the middle storey touched "// &
                 trim(itoa(int(sys%stats%update_columns)))//" columns in two updates")
      if (allocated(error)) return
      ! static: K + kd b b' only
      cols = sys%stats%update_columns
      call spd_factor(sys, 0.0_dp, 0.0_dp, kd, err)
      call pass(err, error)
      if (allocated(error)) return
      kd(mid) = stick_kd()
      call spd_update_device(sys, mid, kd(mid), err)
      call pass(err, error)
      if (allocated(error)) return
      call check(error, sys%stats%update_columns - cols >= n/2 - 1, "a static update touched only "// &
                 trim(itoa(int(sys%stats%update_columns - cols)))//" columns")
      if (allocated(error)) return
      x = b
      call spd_solve(sys, x, err)
      call pass(err, error)
      if (allocated(error)) return
      call dense_k(pb, a)
      do d = 1, n
         call add_link(a, pb%di(d), pb%dj(d), kd(d))
      end do
      call cholesky_factor(a, info)
      xref = b
      call cholesky_solve(a, xref)
      diff = rel_diff(x, xref)
      call check(error, diff <= 1.0e-10_dp, "static update differs from dense by "//trim(rtoa(diff)))
   end subroutine test_local_update

   !> The automatic choice: dense for a few DOFs, band for a long chain.
   subroutine test_auto_path(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem) :: pb
      type(spd_system) :: sys

      call seed(9)
      call chain(spd_dense_max_n, pb, .true.)
      call setup(pb, sys, spd_auto, spd_choose, error=error)
      if (allocated(error)) return
      call check(error, spd_is_dense(sys), "a system of spd_dense_max_n DOFs should be dense")
      if (allocated(error)) return
      call chain(1000, pb, .true.)
      call setup(pb, sys, spd_auto, spd_choose, error=error)
      if (allocated(error)) return
      call check(error, .not. spd_is_dense(sys), "a 1000-storey chain should be banded")
      if (allocated(error)) return
      call check(error, spd_bandwidth(sys), 1)
   end subroutine test_auto_path

   !> Bad input and misuse come back as errors naming what is wrong.
   subroutine test_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem) :: pb
      type(spd_system) :: sys
      type(lib_error), allocatable :: err
      real(dp), allocatable :: x(:)
      integer :: path

      call seed(10)
      call chain(6, pb, .false.)
      pb%mass(3) = 0.0_dp
      call pair_setup(sys, pb%mass, pb%si, pb%sj, pb%sk, pb%di, pb%dj, err)
      call expect(err, "mass(3)", error)
      if (allocated(error)) return
      pb%mass(3) = 1.0_dp
      pb%sj(2) = 7
      call pair_setup(sys, pb%mass, pb%si, pb%sj, pb%sk, pb%di, pb%dj, err)
      call expect(err, "spring 2 joins nodes 2 and 7, outside 0..6", error)
      if (allocated(error)) return
      pb%sj(2) = 1
      pb%sk(4) = -1.0_dp
      call pair_setup(sys, pb%mass, pb%si, pb%sj, pb%sk, pb%di, pb%dj, err)
      call expect(err, "spring 4 has the coefficient -1.0", error)
      if (allocated(error)) return
      pb%sk(4) = 1.0e3_dp
      call pair_setup(sys, pb%mass, pb%si, pb%sj, pb%sk, pb%di, pb%dj, err, path=5)
      call expect(err, "path = 5", error)
      if (allocated(error)) return
      call pair_setup(sys, pb%mass, pb%si, pb%sj, pb%sk, pb%di, pb%dj, err, dashpot_i=[1], dashpot_c=[1.0_dp])
      call expect(err, "spd_setup: dashpot_i, dashpot_j and dashpot_c go together", error)
      if (allocated(error)) return
      call kx_alone(pb, err)
      call expect(err, "spd_setup: kx_i, kx_j and kx_v go together", error)
      if (allocated(error)) return
      do path = spd_dense, spd_banded
         call pair_setup(sys, pb%mass, pb%si, pb%sj, pb%sk, pb%di, pb%dj, err, path=path)
         call pass(err, error)
         if (allocated(error)) return
         x = [1.0_dp, 2.0_dp, 3.0_dp, 4.0_dp, 5.0_dp, 6.0_dp]
         call spd_solve(sys, x, err)
         call expect(err, "not factored", error)
         if (allocated(error)) return
         call spd_update_device(sys, 1, 1.0_dp, err)
         call expect(err, "not factored", error)
         if (allocated(error)) return
         call spd_factor(sys, c0, c1, [1.0_dp], err)
         call expect(err, "1 device stiffnesses given for 6 devices", error)
         if (allocated(error)) return
         call spd_factor(sys, c0, c1, [0.0_dp, 0.0_dp, -2.0_dp, 0.0_dp, 0.0_dp, 0.0_dp], err)
         call expect(err, "device 3 stiffness -2.0", error)
         if (allocated(error)) return
         call spd_factor(sys, c0, c1, [(0.0_dp, path=1, 6)], err)
         call pass(err, error)
         if (allocated(error)) return
         call spd_update_device(sys, 7, 1.0_dp, err)
         call expect(err, "device 7 is not in 1..6", error)
         if (allocated(error)) return
         call spd_update_devices(sys, [1.0_dp], err)
         call expect(err, "spd_update_devices: 1 device stiffnesses given for 6 devices", error)
         if (allocated(error)) return
         call spd_update_devices(sys, [0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, -2.0_dp, 0.0_dp], err)
         call expect(err, "spd_update_devices: device 5 stiffness -2.0", error)
         if (allocated(error)) return
      end do
      ! a free-floating structure without inertia is singular: said so, not solved
      pb%sj(1) = 2
      pb%si(1) = 1
      pb%sj(2) = 3
      call pair_setup(sys, pb%mass, pb%si, pb%sj, pb%sk, pb%di(2:), pb%dj(2:), err, path=spd_banded)
      call pass(err, error)
      if (allocated(error)) return
      call spd_factor(sys, 0.0_dp, 0.0_dp, [(0.0_dp, path=1, 5)], err)
      call expect(err, "not positive definite", error)
      if (allocated(error)) return
      x = [1.0_dp, 2.0_dp, 3.0_dp, 4.0_dp, 5.0_dp, 6.0_dp]
      call spd_solve(sys, x, err)
      call expect(err, "not factored", error)
   end subroutine test_errors

   !> spd_setup given K_x's rows and values without its columns.
   subroutine kx_alone(pb, err)
      type(problem), intent(in) :: pb
      type(lib_error), allocatable, intent(out) :: err
      type(spd_system) :: sys
      integer :: ptr(size(pb%di) + 1), dof(2*size(pb%di))
      real(dp) :: coef(2*size(pb%di))

      call pair_terms(pb%di, pb%dj, ptr, dof, coef)
      call spd_setup(sys, pb%mass, pb%si, pb%sj, pb%sk, ptr, dof, coef, err, kx_i=[1], kx_v=[1.0_dp])
   end subroutine kx_alone

   subroutine expect(err, text, error)
      type(lib_error), allocatable, intent(in) :: err
      character(len=*), intent(in) :: text
      type(error_type), allocatable, intent(out) :: error

      if (.not. allocated(err)) then
         call test_failed(error, "expected an error containing '"//text//"'")
      else if (index(err%message, text) == 0) then
         call test_failed(error, "error '"//err%message//"' does not contain '"//text//"'")
      end if
   end subroutine expect

   pure function itoa(i) result(s)
      integer, intent(in) :: i
      character(len=12) :: s
      write (s, '(i0)') i
   end function itoa

   pure function rtoa(x) result(s)
      real(dp), intent(in) :: x
      character(len=12) :: s
      write (s, '(es10.3)') x
   end function rtoa

   !> The narrow-band factor (band_potf2) against LAPACK's dpbtf2, whose loops and BLAS calls
   !> it writes out: the same bits on random positive definite bands of 0 to 8 superdiagonals
   !> (diagonally dominant, as an effective stiffness is, and merely positive definite), and
   !> the same column for the first pivot that is not positive.
   subroutine test_band_potf2(error)
      type(error_type), allocatable, intent(out) :: error
      external :: dpbtf2   ! LAPACK (fd_banded declares its interface)
      real(dp), allocatable :: a(:, :), b(:, :), c(:, :)
      integer :: kd, n, i, j, trial, info_a, info_b
      integer, parameter :: sizes(3) = [1, 7, 60]

      call seed(17)
      do kd = 0, 8
         do trial = 1, 3
            n = sizes(trial)
            allocate (a(kd + 1, n), c(kd + 1, n))
            ! trials 1 and 2: a dominant diagonal; 3: the diagonal scaled down to about the
            ! edge of definiteness (positive definite or not: both must agree)
            do j = 1, n
               do i = 1, kd
                  a(i, j) = urand(-1.0_dp, 1.0_dp)
               end do
               a(kd + 1, j) = real(2*kd, dp)*merge(1.0_dp, 0.51_dp, trial < 3) + urand(0.0_dp, 1.0_dp)
            end do
            c = a
            call band_potf2(n, kd, a, kd + 1, info_a)
            call dpbtf2('U', n, kd, c, kd + 1, info_b)
            call check(error, info_a, info_b, "info, band of "//trim(itoa(kd)))
            if (allocated(error)) return
            if (info_a == 0) then
               call check(error, all(a == c), "the factor differs from dpbtf2's, band of "//trim(itoa(kd)))
               if (allocated(error)) return
            end if
            deallocate (a, c)
         end do
         ! not positive definite at column 5: both stop there
         n = 9
         allocate (b(kd + 1, n), c(kd + 1, n))
         b = 0.0_dp
         b(kd + 1, :) = 1.0_dp
         if (kd > 0) b(kd, 5) = 2.0_dp   ! A(4, 5) = 2 > sqrt(A(4, 4) A(5, 5))
         if (kd == 0) b(1, 5) = -1.0_dp
         c = b
         call band_potf2(n, kd, b, kd + 1, info_a)
         call dpbtf2('U', n, kd, c, kd + 1, info_b)
         call check(error, info_a, 5, "info of an indefinite band of "//trim(itoa(kd)))
         if (allocated(error)) return
         call check(error, info_b, 5, "dpbtf2's info of an indefinite band of "//trim(itoa(kd)))
         if (allocated(error)) return
         deallocate (b, c)
      end do
   end subroutine test_band_potf2

   !> The Newmark product K (x + a1 z) + a0 M z of a few DOFs (the dense path up to
   !> spd_dense_max_n DOFs, two DOFs written out) is the reference dsymv's loops on the upper
   !> triangle, in their order: the same bits as those loops written here; and its two-DOF
   !> solve agrees with the dense reference. Chains of 1 to 8 DOFs, zeros (signed) included.
   subroutine test_small_kc(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem) :: pb
      type(spd_system) :: sys
      type(lib_error), allocatable :: err
      real(dp), allocatable :: k(:, :), x(:), z(:), y(:), yref(:), w(:), kw(:), kd(:), b(:)
      real(dp) :: temp1, temp2, alpha, diff
      integer :: n, i, j, trial

      call seed(23)
      do n = 1, spd_dense_max_n
         call chain(n, pb, .true.)
         pb%pi = [integer ::]
         pb%pj = [integer ::]
         pb%pc = [real(dp) ::]
         pb%a0 = 1.0e3_dp  ! the mass term as large as the stiffness term: no rounding hides either
         call setup(pb, sys, spd_dense, spd_choose, error=error)
         if (allocated(error)) return
         call dense_k(pb, k)
         do trial = 1, 20
            call random_vector(n, x)
            call random_vector(n, z)
            call random_vector(n, y)
            if (trial == 2) then  ! at rest: the products are signed zeros
               x = 0.0_dp
               z = -0.0_dp
               y = -0.0_dp
            end if
            alpha = -1.0_dp
            if (trial > 2) alpha = urand(-2.0_dp, 2.0_dp)
            ! the reference: dsymv ('U', n, 1, K, w) then y + alpha (K w + a0 M z)
            w = x + pb%a1*z
            allocate (kw(n))
            kw = 0.0_dp
            do j = 1, n
               temp1 = w(j)
               temp2 = 0.0_dp
               do i = 1, j - 1
                  kw(i) = kw(i) + temp1*k(i, j)
                  temp2 = temp2 + k(i, j)*w(i)
               end do
               kw(j) = kw(j) + temp1*k(j, j) + temp2
            end do
            yref = y
            do i = 1, n
               yref(i) = yref(i) + alpha*(kw(i) + pb%a0*pb%mass(i)*z(i))
            end do
            deallocate (kw)
            call spd_kc_matvec(sys, x, z, y, alpha)
            call check(error, all(y == yref .and. (sign(1.0_dp, y) == sign(1.0_dp, yref))), &
                       "n = "//trim(itoa(n))//": K^ product differs from dsymv's order")
            if (allocated(error)) return
         end do
         if (n == 2) then
            allocate (kd(n))
            kd = [stick_kd(), 0.0_dp]
            call random_vector(n, b)
            call spd_factor(sys, c0, c1, kd, err)
            call pass(err, error)
            if (allocated(error)) return
            call compare(pb, sys, kd, b, diff, error)
            if (allocated(error)) return
            call check(error, diff <= 1.0e-14_dp, "two DOFs: solve differs from dense by "//trim(rtoa(diff)))
            if (allocated(error)) return
         end if
      end do
   end subroutine test_small_kc


   !> The ordering equals the plain quadratic implementation kept below (ref_rcm_order) on
   !> random graphs: connected or not, with isolated nodes, repeated edges, self-loops and
   !> edges to the table, and on randomly numbered chains and frames.
   subroutine test_rcm_reference(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem) :: pb
      integer, allocatable :: ei(:), ej(:), perm(:), ref(:)
      integer :: trial, n, ne, e

      call seed(3)
      do trial = 1, 300
         n = 1 + mod(trial*7, 60)
         ne = int(urand(0.0_dp, 2.5_dp*n))
         allocate (ei(ne), ej(ne), perm(n), ref(n))
         do e = 1, ne
            ei(e) = min(n, int(urand(0.0_dp, n + 1.0_dp)))   ! 0 (the table) .. n
            ej(e) = min(n, int(urand(0.0_dp, n + 1.0_dp)))
            if (mod(e, 5) == 0 .and. e > 1) then               ! a repeated edge, reversed
               ei(e) = ej(e - 1); ej(e) = ei(e - 1)
            end if
         end do
         call rcm_order(n, ei, ej, perm)
         call ref_rcm_order(n, ei, ej, ref)
         call check(error, all(perm == ref), "trial "//trim(itoa(trial))//": n = "//trim(itoa(n))// &
                    ", "//trim(itoa(ne))//" edges: the ordering differs from the reference")
         if (allocated(error)) return
         deallocate (ei, ej, perm, ref)
      end do
      do trial = 1, 6
         if (trial <= 3) then
            call chain(40*trial, pb, .true.)
         else
            call frame(trial, 3*trial, pb, .true.)
         end if
         ei = [pb%si, pb%di, pb%pi]
         ej = [pb%sj, pb%dj, pb%pj]
         allocate (perm(pb%n), ref(pb%n))
         call rcm_order(pb%n, ei, ej, perm)
         call ref_rcm_order(pb%n, ei, ej, ref)
         call check(error, all(perm == ref), "structure "//trim(itoa(trial))//": the ordering differs")
         if (allocated(error)) return
         deallocate (perm, ref)
      end do
   end subroutine test_rcm_reference

   !> 200 000 masses without a connection between them and a star of 100 000 leaves listed
   !> from the last are ordered in well under a second (a quadratic ordering takes many seconds):
   !> the free masses by number, reversed; the star as leaf 2, the hub, leaves 3, 4, ...,
   !> reversed.
   subroutine test_rcm_linear(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: nfree = 200000, nleaf = 100000
      integer, allocatable :: ei(:), ej(:), perm(:)
      real :: t0, t1
      integer :: i

      allocate (ei(nfree), ej(nfree), perm(nfree))
      ei = [(i, i=1, nfree)]
      ej = 0                                   ! every mass on a spring to the table
      call cpu_time(t0)
      call rcm_order(nfree, ei, ej, perm)
      call cpu_time(t1)
      call check(error, all(perm == [(nfree + 1 - i, i=1, nfree)]), "free masses: not in reverse order")
      if (allocated(error)) return
      call check(error, t1 - t0 < 1.0, "ordering 200000 free masses took "//trim(rtoa(real(t1 - t0, dp)))//" s")
      if (allocated(error)) return
      deallocate (ei, ej, perm)
      allocate (perm(nleaf + 1))
      ei = [(1, i=1, nleaf)]
      ej = [(nleaf + 2 - i, i=1, nleaf)]       ! leaves nleaf+1, nleaf, ..., 2
      call cpu_time(t0)
      call rcm_order(nleaf + 1, ei, ej, perm)
      call cpu_time(t1)
      call check(error, all(perm == [[(nleaf + 2 - i, i=1, nleaf - 1)], 1, 2]), "star: not leaf 2, hub, leaves 3..")
      if (allocated(error)) return
      call check(error, t1 - t0 < 1.0, "ordering a star of 100000 leaves took "//trim(rtoa(real(t1 - t0, dp)))//" s")
   end subroutine test_rcm_linear

   ! ---------------------------------------------------------------- reference ordering

   !> The same ordering written plainly (a search of all nodes for the seed of each component,
   !> insertion sorts of the adjacency lists: quadratic), the reference of test_rcm_reference.
   pure subroutine ref_rcm_order(n, edge_i, edge_j, perm)
      integer, intent(in) :: n              !! number of nodes (1..n)
      integer, intent(in) :: edge_i(:)      !! first node of each edge (0 = table, ignored)
      integer, intent(in) :: edge_j(:)      !! second node of each edge (0 = table, ignored)
      integer, intent(out) :: perm(:)       !! new -> old, size n
      integer, allocatable :: start(:), adj(:), deg(:), level(:), order(:)
      logical, allocatable :: done(:)
      integer :: nn, i, e, root, nlev, nlev2, first, last, last2, cand, head, tail, v, w, k

      if (n == 0) return
      call ref_adjacency(n, edge_i, edge_j, start, adj, deg)
      allocate (level(n), order(n), done(n))
      level = -1
      done = .false.
      nn = 0
      do
         ! seed of the next component: an unnumbered node of least degree
         root = 0
         do i = 1, n
            if (done(i)) cycle
            if (root == 0) then
               root = i
            else if (deg(i) < deg(root)) then
               root = i
            end if
         end do
         if (root == 0) exit
         ! George-Liu: move to a node of least degree in the last level while the
         ! eccentricity grows
         call ref_levels(root, nn, start, adj, done, level, order, first, last, nlev)
         do
            cand = order(first)
            do k = first, last
               if (deg(order(k)) < deg(cand)) cand = order(k)
            end do
            call ref_clear(order(nn + 1:last), level)
            call ref_levels(cand, nn, start, adj, done, level, order, first, last2, nlev2)
            if (nlev2 > nlev) then
               root = cand
               nlev = nlev2
               last = last2
            else
               call ref_clear(order(nn + 1:last2), level)
               exit
            end if
         end do
         call ref_clear(order(nn + 1:last), level)
         ! Cuthill-McKee from root: neighbours by increasing degree (adj is sorted so)
         head = nn + 1
         tail = nn + 1
         order(tail) = root
         done(root) = .true.
         do while (head <= tail)
            v = order(head)
            head = head + 1
            do e = start(v), start(v + 1) - 1
               w = adj(e)
               if (done(w)) cycle
               done(w) = .true.
               tail = tail + 1
               order(tail) = w
            end do
         end do
         nn = tail
      end do
      do k = 1, n
         perm(k) = order(n + 1 - k)
      end do

   end subroutine ref_rcm_order

   !> Breadth-first level structure from r over the nodes not yet numbered, written to
   !> order(nn+1:last); the last level is order(first:last), nlev the number of levels.
   pure subroutine ref_levels(r, nn, start, adj, done, level, order, first, last, nlev)
      integer, intent(in) :: r, nn
      integer, intent(in) :: start(:), adj(:)
      logical, intent(in) :: done(:)
      integer, intent(inout) :: level(:), order(:)
      integer, intent(out) :: first, last, nlev
      integer :: h, x, y, q

      last = nn + 1
      order(last) = r
      level(r) = 1
      h = nn + 1
      do while (h <= last)
         x = order(h)
         h = h + 1
         do q = start(x), start(x + 1) - 1
            y = adj(q)
            if (level(y) >= 0 .or. done(y)) cycle
            level(y) = level(x) + 1
            last = last + 1
            order(last) = y
         end do
      end do
      nlev = level(order(last))
      first = last
      do while (first > nn + 1)
         if (level(order(first - 1)) /= nlev) exit
         first = first - 1
      end do
   end subroutine ref_levels

   !> Reset the levels of the given nodes.
   pure subroutine ref_clear(nodes, level)
      integer, intent(in) :: nodes(:)
      integer, intent(inout) :: level(:)

      level(nodes) = -1
   end subroutine ref_clear

   !> Adjacency lists (compressed, without self-loops and repeated edges), each sorted by
   !> increasing degree, then node number.
   pure subroutine ref_adjacency(n, edge_i, edge_j, start, adj, deg)
      integer, intent(in) :: n
      integer, intent(in) :: edge_i(:), edge_j(:)
      integer, allocatable, intent(out) :: start(:), adj(:), deg(:)
      integer, allocatable :: fill(:), raw(:)
      integer :: e, a, b, v, k, m, x, cnt

      allocate (start(n + 1), fill(n), deg(n))
      fill = 0
      do e = 1, size(edge_i)
         a = edge_i(e); b = edge_j(e)
         if (a <= 0 .or. b <= 0 .or. a == b) cycle
         fill(a) = fill(a) + 1
         fill(b) = fill(b) + 1
      end do
      start(1) = 1
      do v = 1, n
         start(v + 1) = start(v) + fill(v)
      end do
      allocate (raw(start(n + 1) - 1))
      fill = start(1:n)
      do e = 1, size(edge_i)
         a = edge_i(e); b = edge_j(e)
         if (a <= 0 .or. b <= 0 .or. a == b) cycle
         raw(fill(a)) = b
         fill(a) = fill(a) + 1
         raw(fill(b)) = a
         fill(b) = fill(b) + 1
      end do
      ! drop repeated neighbours (sort each list by node number first)
      cnt = 0
      do v = 1, n
         call ref_insertion_sort(raw(start(v):start(v + 1) - 1))
         m = cnt
         do k = start(v), start(v + 1) - 1
            if (k > start(v)) then
               if (raw(k) == raw(k - 1)) cycle
            end if
            m = m + 1
            raw(m) = raw(k)
         end do
         start(v) = cnt + 1
         deg(v) = m - cnt
         cnt = m
      end do
      start(n + 1) = cnt + 1
      adj = raw(1:cnt)
      ! neighbours by increasing degree (stable: equal degrees keep node order)
      do v = 1, n
         do k = start(v) + 1, start(v + 1) - 1
            x = adj(k)
            m = k - 1
            do while (m >= start(v))
               if (deg(adj(m)) <= deg(x)) exit
               adj(m + 1) = adj(m)
               m = m - 1
            end do
            adj(m + 1) = x
         end do
      end do
   end subroutine ref_adjacency

   pure subroutine ref_insertion_sort(a)
      integer, intent(inout) :: a(:)
      integer :: k, m, x

      do k = 2, size(a)
         x = a(k)
         m = k - 1
         do while (m >= 1)
            if (a(m) <= x) exit
            a(m + 1) = a(m)
            m = m - 1
         end do
         a(m + 1) = x
      end do
   end subroutine ref_insertion_sort

   !> Devices along general directions (three or four terms, coefficients other than 1, a
   !> term on the table side dropped): the factor of K^ = K + c1 C + c0 M + sum kd b b' solves
   !> as the dense Cholesky of the same matrix assembled by hand, after the set-up and after
   !> rank-one updates and downdates of each device, on both storages.
   subroutine test_general_devices(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 12, nd = 3
      integer, parameter :: ptr(nd + 1) = [1, 4, 8, 11]
      integer, parameter :: dof(10) = [2, 5, 9, 1, 3, 4, 12, 7, 11, 8]
      real(dp), parameter :: coef(10) = [0.8_dp, -0.6_dp, 0.25_dp, 1.0_dp, -0.5_dp, 0.3_dp, -1.2_dp, &
                                         0.7_dp, 0.7_dp, -1.0_dp]
      real(dp), parameter :: a0 = 0.3_dp, a1 = 2.0e-3_dp
      type(spd_system) :: sys
      type(lib_error), allocatable :: err
      real(dp) :: mass(n), sk(n), kmat(n, n), a(n, n), x(n), y(n), kd(nd), diff
      real(dp), allocatable :: b(:)
      integer :: si(n), sj(n), i, k, l, d, path, step, info

      call seed(17)
      kmat = 0.0_dp
      do i = 1, n
         mass(i) = urand(1.0_dp, 2.0_dp)
         si(i) = i; sj(i) = i - 1; sk(i) = urand(1.0e3_dp, 2.0e3_dp)
         kmat(i, i) = kmat(i, i) + sk(i)
      end do
      do i = 2, n
         kmat(i - 1, i - 1) = kmat(i - 1, i - 1) + sk(i)
         kmat(i, i - 1) = kmat(i, i - 1) - sk(i)
         kmat(i - 1, i) = kmat(i - 1, i) - sk(i)
      end do
      call random_vector(n, b)
      kd = [4.0e3_dp, 0.0_dp, 2.5e4_dp]
      do path = spd_dense, spd_banded
         call spd_setup(sys, mass, si, sj, sk, ptr, dof, coef, err, a0=a0, a1=a1, path=path)
         call pass(err, error)
         if (allocated(error)) return
         if (path == spd_banded) then
            ! the band covers each device's span: device 2 joins DOFs 1 and 12
            call check(error, spd_bandwidth(sys) >= 1, "bandwidth")
            if (allocated(error)) return
         end if
         call spd_factor(sys, c0, c1, kd, err)
         call pass(err, error)
         if (allocated(error)) return
         do step = 0, 3
            if (step == 1) kd(2) = 9.0e3_dp
            if (step == 2) kd(3) = 1.0e2_dp
            if (step == 3) kd(1) = 0.0_dp
            if (step > 0) then
               call spd_update_devices(sys, kd, err)
               call pass(err, error)
               if (allocated(error)) return
            end if
            ! the same matrix by hand
            a = (1.0_dp + c1*a1)*kmat
            do i = 1, n
               a(i, i) = a(i, i) + (c0 + c1*a0)*mass(i)
            end do
            do d = 1, nd
               do k = ptr(d), ptr(d + 1) - 1
                  do l = ptr(d), ptr(d + 1) - 1
                     a(dof(k), dof(l)) = a(dof(k), dof(l)) + kd(d)*coef(k)*coef(l)
                  end do
               end do
            end do
            call cholesky_factor(a, info)
            call check(error, info == 0, "dense factor")
            if (allocated(error)) return
            y = b
            call cholesky_solve(a, y)
            x = b
            call spd_solve(sys, x, err)
            call pass(err, error)
            if (allocated(error)) return
            diff = maxval(abs(x - y))/maxval(abs(y))
            call check(error, diff <= 1.0e-12_dp, "path "//trim(itoa(path))//", step "//trim(itoa(step))// &
                       ": solve differs from the dense Cholesky by "//trim(rtoa(diff)))
            if (allocated(error)) return
         end do
      end do
      ! a term outside the DOFs, a zero coefficient, a DOF twice: named
      call spd_setup(sys, mass, si, sj, sk, [1, 3], [2, 13], [1.0_dp, -1.0_dp], err)
      call expect(err, "device 1 has a term at DOF 13, outside 1..12", error)
      if (allocated(error)) return
      call spd_setup(sys, mass, si, sj, sk, [1, 3], [2, 3], [1.0_dp, 0.0_dp], err)
      call expect(err, "device 1 has the coefficient 0 at DOF 3", error)
      if (allocated(error)) return
      call spd_setup(sys, mass, si, sj, sk, [1, 2, 4], [2, 3, 3], [1.0_dp, 1.0_dp, -1.0_dp], err)
      call expect(err, "device 2 has two terms at DOF 3", error)
   end subroutine test_general_devices

   !> spd_setup for devices between two nodes (di, dj; 0 = the table).
   subroutine pair_setup(sys, mass, si, sj, sk, di, dj, error, a0, a1, dashpot_i, dashpot_j, dashpot_c, &
                         path, budget, method)
      type(spd_system), intent(out) :: sys
      real(dp), intent(in) :: mass(:), sk(:)
      integer, intent(in) :: si(:), sj(:), di(:), dj(:)
      type(lib_error), allocatable, intent(out) :: error
      real(dp), intent(in), optional :: a0, a1, budget
      integer, intent(in), optional :: dashpot_i(:), dashpot_j(:), path, method
      real(dp), intent(in), optional :: dashpot_c(:)
      integer :: ptr(size(di) + 1), dof(2*size(di))
      real(dp) :: coef(2*size(di))

      call pair_terms(di, dj, ptr, dof, coef)
      call spd_setup(sys, mass, si, sj, sk, ptr, dof, coef, error, a0=a0, a1=a1, dashpot_i=dashpot_i, &
                     dashpot_j=dashpot_j, dashpot_c=dashpot_c, path=path, budget=budget, method=method)
   end subroutine pair_setup

end module test_fd_banded
