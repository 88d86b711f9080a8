!> Unit tests of the one-step problem of Moreau-Jean time stepping (fd_impulse_solver):
!> every solution is checked against the complementarity conditions directly, and against an
!> independent solution, the box LCP of the dense Delassus operator B'W^-1 B solved by
!> Lemke's method (fd_lcp). Cases: random chains and two-column frames with loops of
!> devices, the Lemke fallback, identical devices in parallel, a symmetric structure, a
!> chain whose proportional slip loads make every device stop at once, locked edges.
module test_fd_impulse_solver
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_error, only: fd_error_type => error_type
   use fd_linalg, only: cholesky_factor, cholesky_solve
   use fd_lcp, only: lcp_work, lcp_info, lcp_init, box_lcp_solve, lcp_solved
   use fd_stick_groups, only: add_edge, edge_relative
   use fd_impulse_solver, only: impulse_solver, solver_setup, solve_impulses
   use test_fd_helpers, only: check_close
   use test_fd_mj_models, only: mj_model, rng_type, uniform, chain_model, frame_model, dense_w, dense_b
   implicit none
   private

   public :: collect_impulse_solver

   real(dp), parameter :: vtol = 1.0e-12_dp  !! agreement with the dense reference, relative (measured: 1e-15)

contains

   subroutine collect_impulse_solver(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("random chains: equal to Lemke on the Delassus", test_random_chains), &
                  new_unittest("random frames with loops: equal to Lemke", test_random_frames), &
                  new_unittest("Lemke fallback: the same solution", test_fallback), &
                  new_unittest("identical devices in parallel act as one", test_parallel), &
                  new_unittest("symmetric structure: symmetric solution", test_symmetric), &
                  new_unittest("proportional slip loads: all stop at once", test_proportional), &
                  new_unittest("locked edges keep their impulse", test_locked) &
                  ]
   end subroutine collect_impulse_solver

   !> The reference: Lemke on the box LCP of the dense Delassus operator, v = W^-1 (r - B z).
   subroutine reference(m, alpha, beta, r, v, error)
      type(mj_model), intent(in) :: m
      real(dp), intent(in) :: alpha, beta, r(:)
      real(dp), intent(out) :: v(:)
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: w(:, :), b(:, :), y(:, :), a(:, :), q(:), z(:), wz(:)
      type(lcp_work) :: work
      type(lcp_info) :: info
      type(fd_error_type), allocatable :: err
      integer :: nd, d, infoc

      nd = size(m%di)
      allocate (w(m%n, m%n), y(m%n, nd), q(nd), z(nd), wz(nd))
      call dense_w(m, alpha, beta, w)
      call dense_b(m, b)
      call cholesky_factor(w, infoc)
      do d = 1, nd
         y(:, d) = b(:, d)
         call cholesky_solve(w, y(:, d))
      end do
      a = matmul(transpose(b), y)
      v = r
      call cholesky_solve(w, v)
      q = -matmul(transpose(b), v)
      call lcp_init(work, nd, nd, err)
      call box_lcp_solve(work, a, q, -m%pmu, m%pmu, z, wz, info)
      call check(error, info%status == lcp_solved, "reference Lemke solved")
      if (allocated(error)) return
      v = v - matmul(y, z)
   end subroutine reference

   !> Solve with the solver from a random first pattern; check the conditions and the
   !> reference; return the solver's counts.
   subroutine solve_and_check(m, alpha, beta, r, rng, error, max_iter, p_out, v_out)
      type(mj_model), intent(in) :: m
      real(dp), intent(in) :: alpha, beta, r(:)
      type(rng_type), intent(inout) :: rng
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: max_iter
      type(impulse_solver), intent(out), optional :: p_out
      real(dp), intent(out), optional :: v_out(:)
      type(impulse_solver) :: p
      type(fd_error_type), allocatable :: err
      real(dp), allocatable :: v1(:), vref(:), res(:), wmat(:, :)
      real(dp) :: tol, x
      integer :: e

      call solver_setup(p, m%mass, m%si, m%sj, m%sk, m%di, m%dj, m%pmu, err)
      call check(error, .not. allocated(err), "set-up")
      if (allocated(error)) return
      if (present(max_iter)) p%max_iter = max_iter
      do e = 1, p%ne
         x = uniform(rng, 0.0_dp, 3.0_dp)
         p%sigma(e) = int(x) - 1
      end do
      allocate (v1(m%n), vref(m%n), res(m%n), wmat(m%n, m%n))
      call solve_impulses(p, r, abs(r), alpha, beta, p%es%pmu, v1, err)
      call check(error, .not. allocated(err), "solved")
      if (allocated(error)) return
      ! the conditions, directly
      tol = 1.0e-9_dp*maxval(abs(v1))
      do e = 1, p%ne
         x = edge_relative(p%es, e, v1)
         if (p%sigma(e) == 0) then
            call check(error, abs(x) <= tol, "a sticking edge does not move")
            if (allocated(error)) return
            call check(error, abs(p%lam(e)) <= p%es%pmu(e)*(1.0_dp + 1.0e-9_dp), "sticking impulse within its bound")
         else
            call check(error, p%lam(e) == p%sigma(e)*p%es%pmu(e), "sliding impulse at its bound")
            if (allocated(error)) return
            call check(error, p%sigma(e)*x >= -tol, "sliding the way the impulse opposes")
         end if
         if (allocated(error)) return
      end do
      ! equilibrium W v1 = r - B lambda
      call dense_w(m, alpha, beta, wmat)
      res = matmul(wmat, v1) - r
      do e = 1, p%ne
         call add_edge(p%es, e, p%lam(e), res)
      end do
      call check_close(error, maxval(abs(res)), 0.0_dp, 1.0e-12_dp*(maxval(abs(r)) + maxval(p%es%pmu)), &
                       "equilibrium W v1 = r - B lambda", absolute=.true.)
      if (allocated(error)) return
      ! the dense reference
      call reference(m, alpha, beta, r, vref, error)
      if (allocated(error)) return
      call check_close(error, maxval(abs(v1 - vref)), 0.0_dp, &
                       vtol*(maxval(abs(vref)) + maxval(abs(r)/(alpha*m%mass))), "v1 = Lemke's", absolute=.true.)
      if (allocated(error)) return
      if (present(p_out)) p_out = p
      if (present(v_out)) v_out = v1
   end subroutine solve_and_check

   subroutine random_rhs(rng, m, scale, r)
      type(rng_type), intent(inout) :: rng
      type(mj_model), intent(in) :: m
      real(dp), intent(in) :: scale
      real(dp), allocatable, intent(out) :: r(:)
      integer :: i

      allocate (r(m%n))
      do i = 1, m%n
         r(i) = m%mass(i)*uniform(rng, -scale, scale)
      end do
   end subroutine random_rhs

   subroutine test_random_chains(error)
      type(error_type), allocatable, intent(out) :: error
      type(mj_model) :: m
      type(rng_type) :: rng
      real(dp), allocatable :: r(:)
      integer :: k

      rng%s = 101
      do k = 1, 30
         call chain_model(rng, 3 + mod(k, 12), m)
         call random_rhs(rng, m, uniform(rng, 0.2_dp, 4.0_dp), r)
         call solve_and_check(m, uniform(rng, 0.5_dp, 2.0_dp), uniform(rng, 0.0_dp, 0.05_dp), r, rng, error)
         if (allocated(error)) return
      end do
   end subroutine test_random_chains

   subroutine test_random_frames(error)
      type(error_type), allocatable, intent(out) :: error
      type(mj_model) :: m
      type(rng_type) :: rng
      real(dp), allocatable :: r(:)
      integer :: k

      rng%s = 202
      do k = 1, 30
         call frame_model(rng, 3 + mod(k, 6), m)
         call random_rhs(rng, m, uniform(rng, 0.2_dp, 4.0_dp), r)
         call solve_and_check(m, uniform(rng, 0.5_dp, 2.0_dp), uniform(rng, 0.0_dp, 0.05_dp), r, rng, error)
         if (allocated(error)) return
      end do
   end subroutine test_random_frames

   !> One active-set pattern only: Lemke on the devices in doubt must still give the solution.
   subroutine test_fallback(error)
      type(error_type), allocatable, intent(out) :: error
      type(mj_model) :: m
      type(rng_type) :: rng
      type(impulse_solver) :: p
      real(dp), allocatable :: r(:)
      integer :: k, fallbacks

      rng%s = 303
      fallbacks = 0
      do k = 1, 20
         if (mod(k, 2) == 0) then
            call chain_model(rng, 10, m)
         else
            call frame_model(rng, 5, m)
         end if
         call random_rhs(rng, m, 3.0_dp, r)
         call solve_and_check(m, 1.0_dp, 0.01_dp, r, rng, error, max_iter=1, p_out=p)
         if (allocated(error)) return
         fallbacks = fallbacks + p%fallbacks
      end do
      call check(error, fallbacks >= 10, "the fallback was exercised")
   end subroutine test_fallback

   !> Storeys 2 and 4 of a chain get a second, identical device: the solution is the chain's
   !> with those devices' P mu doubled, each of the pair carrying half the impulse.
   subroutine test_parallel(error)
      type(error_type), allocatable, intent(out) :: error
      type(mj_model) :: m, m2
      type(rng_type) :: rng
      type(impulse_solver) :: p1, p2
      real(dp), allocatable :: r(:), v1(:), v2(:)
      integer :: k

      rng%s = 404
      do k = 1, 10
         call chain_model(rng, 6, m)
         m2 = m
         m2%di = [m%di, 2, 4]
         m2%dj = [m%dj, 1, 3]
         m2%pmu = [m%pmu, m%pmu(2), m%pmu(4)]
         m%pmu(2) = 2.0_dp*m%pmu(2)
         m%pmu(4) = 2.0_dp*m%pmu(4)
         call random_rhs(rng, m, 2.0_dp, r)
         allocate (v1(m%n), v2(m%n))
         call solve_and_check(m, 1.0_dp, 0.01_dp, r, rng, error, p_out=p1, v_out=v1)
         if (allocated(error)) return
         call solve_and_check(m2, 1.0_dp, 0.01_dp, r, rng, error, p_out=p2, v_out=v2)
         if (allocated(error)) return
         call check(error, p2%ne == 6, "the pairs are one edge each")
         if (allocated(error)) return
         call check_close(error, maxval(abs(v1 - v2)), 0.0_dp, 1.0e-13_dp*maxval(abs(v1)), &
                          "parallel pair = one device of twice the slip load", absolute=.true.)
         if (allocated(error)) return
         call check(error, p2%es%dev_share(2) == 0.5_dp .and. p2%es%dev_share(7) == 0.5_dp, "equal shares")
         if (allocated(error)) return
         deallocate (v1, v2)
      end do
   end subroutine test_parallel

   !> Two identical chains on the table, loaded alike: both move alike, to round-off.
   subroutine test_symmetric(error)
      type(error_type), allocatable, intent(out) :: error
      type(mj_model) :: c, m
      type(rng_type) :: rng
      real(dp), allocatable :: r(:), v(:)
      integer :: k, n

      rng%s = 505
      do k = 1, 10
         n = 4 + k
         call chain_model(rng, n, c)
         m%n = 2*n
         m%mass = [c%mass, c%mass]
         m%si = [c%si, c%si + n]
         m%sj = [c%sj, merge(c%sj + n, 0, c%sj > 0)]
         m%sk = [c%sk, c%sk]
         m%di = m%si
         m%dj = m%sj
         m%pmu = [c%pmu, c%pmu]
         call random_rhs(rng, c, 3.0_dp, r)
         r = [r, r]
         allocate (v(2*n))
         call solve_and_check(m, 1.0_dp, 0.02_dp, r, rng, error, v_out=v)
         if (allocated(error)) return
         call check_close(error, maxval(abs(v(1:n) - v(n + 1:))), 0.0_dp, 1.0e-13_dp*maxval(abs(v)), &
                          "the two chains alike", absolute=.true.)
         if (allocated(error)) return
         deallocate (v)
      end do
   end subroutine test_symmetric

   !> A chain sliding as a rigid body with slip loads proportional to the mass above each
   !> storey: friction decelerates every floor alike and no storey can see that the others
   !> stop. Given a small uniform drift velocity, every device must stick at once.
   subroutine test_proportional(error)
      type(error_type), allocatable, intent(out) :: error
      type(mj_model) :: m
      type(rng_type) :: rng
      type(impulse_solver) :: p
      real(dp), allocatable :: r(:), v(:)
      integer :: n, i

      rng%s = 606
      n = 40
      call chain_model(rng, n, m)
      m%mass = 1.0_dp
      do i = 1, n
         m%pmu(i) = 0.1_dp*(n - i + 1)          ! proportional to the mass above storey i
      end do
      ! free velocities 0.001 i (drift 0.001 in every storey): the floors above storey d carry
      ! 0.001 (n + d)(n - d + 1) / 2 <= 0.1 (n - d + 1), its bound, so every device can hold
      allocate (r(n), v(n))
      r = [(0.001_dp*i, i=1, n)]
      call solve_and_check(m, 1.0_dp, 1.0e-4_dp, r, rng, error, p_out=p, v_out=v)
      if (allocated(error)) return
      call check(error, all(p%sigma == 0), "every device sticks")
      if (allocated(error)) return
      call check(error, maxval(abs(v)) == 0.0_dp, "the building stops on the table")
   end subroutine test_proportional

   !> Locked sliding edges (devices moving at t = 0) keep their sign and full impulse even
   !> where sticking would hold (acceleration problem: W = M).
   subroutine test_locked(error)
      type(error_type), allocatable, intent(out) :: error
      type(mj_model) :: m
      type(rng_type) :: rng
      type(impulse_solver) :: p
      type(fd_error_type), allocatable :: err
      real(dp) :: v1(5), r(5)

      rng%s = 707
      call chain_model(rng, 5, m)
      call solver_setup(p, m%mass, m%si, m%sj, m%sk, m%di, m%dj, m%pmu, err)
      call check(error, .not. allocated(err), "set-up")
      if (allocated(error)) return
      r = 0.0_dp                      ! no load: unlocked devices stay stuck
      p%sigma = 0
      p%sigma(3) = -1
      p%locked(3) = .true.
      call solve_impulses(p, r, abs(r) + 1.0_dp, 1.0_dp, 0.0_dp, p%es%pmu, v1, err)
      call check(error, .not. allocated(err), "solved")
      if (allocated(error)) return
      call check(error, p%sigma(3) == -1 .and. p%lam(3) == -m%pmu(3), "the locked edge keeps its impulse")
      if (allocated(error)) return
      call check(error, edge_relative(p%es, 3, v1) > 0.0_dp, "which decelerates its negative slide")
   end subroutine test_locked

end module test_fd_impulse_solver
