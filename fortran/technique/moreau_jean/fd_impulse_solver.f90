!> The one-step problem of Moreau-Jean time stepping with Coulomb friction, solved exactly:
!> find the end-of-step velocities v1 and the friction impulses lambda of the devices with
!>
!>   W v1 = r - B lambda,   W = alpha M + beta K (symmetric positive definite),
!>   w = B' v1,   |lambda_e| <= g_e,   w_e > 0 => lambda_e = g_e,   w_e < 0 => lambda_e = -g_e
!>
!> (each device sticks, w_e = 0 with |lambda_e| <= g_e, or slides with its impulse at the
!> limit opposing its end-of-step relative velocity). v1 minimises the strictly convex
!> 1/2 v'W v - r'v + sum_e g_e |b_e'v|: it is unique; lambda is unique unless sticking
!> devices are redundant (a closed loop), when only B lambda is.
!>
!> **Method: an active-set (block principal pivoting) iteration in full coordinates.** For a
!> pattern (each edge sticking, or sliding with a sign) the problem is linear: the sticking
!> edges are exact constraints, which merge the nodes they join into groups (fd_stick_groups),
!> the sliding ones carry -+g_e; the reduced system T'W T is assembled and factored in band
!> form (fd_group_system; a chain stays a chain), solved, and the sticking impulses are
!> recovered by elimination over each group's spanning tree. The pattern is right when every
!> sliding edge moves its way (sigma_e w_e >= 0) and every sticking impulse is within its
!> bound; otherwise the violating edges change status (sticking to sliding in the direction
!> of their impulse, sliding to sticking) and the pattern is solved again. This is the
!> primal-dual active set strategy, i.e. a semismooth Newton method (Hintermueller, Ito and
!> Kunisch, SIAM J. Optim. 13, 2002), and block principal pivoting for the dual box LCP in
!> lambda (Judice and Pires, Comput. Oper. Res. 21, 1994), with their safeguard: all the
!> violating edges change while the number of violations falls (or for max_backups tries
!> more), then one at a time (the last violating edge, Murty's rule). The first guess is
!> the previous step's pattern corrected by the trend of the last two solutions
!> (predict_pattern); a stop found proposes the stops it causes in its neighbours
!> (expand_stops): devices that stop together are then found together, not one per pattern.
!> The checks' tolerances are 1e-10 of the size of the terms each quantity is summed from
!> (rounding, not an approximation).
!>
!> **Fallback: Lemke on the edges in doubt.** If the iteration has not ended after max_iter
!> patterns (default 2 ne + 50), the edges whose status changed in this call, or is violated, are put in doubt
!> (D); every other edge keeps its status, the reduced system of the others is factored,
!> and the box LCP of the edges in D, with the Delassus operator A = B_D' T (T'W T)^-1 T' B_D
!> (|D| solves) and the free velocities, is solved by Lemke's method (fd_lcp: exact, and
!> always successful for this symmetric positive semidefinite operator). The edges outside D
!> are then checked against the result; those violated join D and the LCP is solved again.
!> D only grows, so this ends, at worst with every edge in D: the whole problem by Lemke.
!>
!> pattern_acceleration gives the acceleration at the end of a step from Coulomb's law at the
!> level of accelerations (no factorization: the groups' masses are diagonal).
!>
!> Only solver_setup allocates (the band storage may grow once a pattern needs a wider
!> band, see fd_group_system; never for a chain).
module fd_impulse_solver
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, allocation_error
   use fd_rcm, only: rcm_order, graph_bandwidth
   use fd_stick_groups, only: edge_set, edges_setup, groups_build, recover_impulses, expand, restrict, &
                              add_edge, edge_relative
   use fd_group_system, only: group_system, gs_setup, gs_factor, gs_solve, gs_k_matvec, gs_k_absmatvec
   use fd_lcp, only: lcp_work, lcp_info, lcp_init, box_lcp_solve, lcp_solved, lcp_status_text
   implicit none
   private

   public :: impulse_solver, solver_setup, solve_impulses, predict_pattern, pattern_acceleration, solver_max_lcp

   !> Largest number of edges in doubt the Lemke fallback takes (its tableau holds
   !> 2 p x (4 p + 2) reals: 4.2 MB at 256).
   integer, parameter :: solver_max_lcp = 256
   integer, parameter :: max_backups = 3          !! full exchanges allowed without progress
   real(dp), parameter :: tol_rel = 1.0e-10_dp    !! tolerance of the checks, relative to their terms

   !> The structure, its devices as edges, the pattern and the work space of the solver.
   type :: impulse_solver
      type(edge_set) :: es                        !! the devices as edges (fd_stick_groups)
      type(group_system) :: gs                    !! springs, masses and the reduced factor
      integer :: n = 0                            !! DOFs
      integer :: ne = 0                           !! edges
      integer :: max_iter = 0                     !! patterns tried before the fallback; 0: 2 ne + 50
      integer, allocatable :: node_order(:)       !! RCM order of the nodes (groups numbered in it)
      integer, allocatable :: sigma(:)            !! (ne) pattern: 0 stick, +1/-1 slide that way
      integer, allocatable :: sa(:)               !! (ne) pattern of the accelerations at a step's end
      real(dp), allocatable :: fa(:)              !! (ne) forces of the devices at rest there [N]
      real(dp), allocatable :: lam(:)             !! (ne) impulses of the solution
      real(dp), allocatable :: w(:)               !! (ne) end-of-step relative velocities b_e'v1
      real(dp), allocatable :: lam_prev(:), w_prev(:) !! (ne) the solution before (predict_pattern)
      real(dp), allocatable :: amax(:)            !! (ne) b_e'M^-1 b_e >= alpha b_e'W^-1 b_e
      integer, allocatable :: queue(:)            !! (ne) work of the stop expansion
      real(dp), allocatable :: wt(:)              !! (ne) its estimated relative velocities
      logical :: have_prev = .false.              !! lam_prev, w_prev hold a solution
      logical, allocatable :: locked(:)           !! (ne) sliding edges whose sign is given (never change)
      logical, allocatable :: fstuck(:)           !! (ne) the sticking edges of the current factor
      real(dp) :: falpha = -1.0_dp                !! its alpha
      real(dp) :: fbeta = -1.0_dp                 !! its beta
      logical :: fvalid = .false.                 !! the factor and the groups are those of fstuck
      ! work
      logical, allocatable :: stuck(:), changed(:), viol(:), doubt(:)
      real(dp), allocatable :: f(:), q(:), rho(:), sc(:), lsc(:), col(:), rabs(:)
      type(lcp_work) :: lcp
      integer :: pmax = 0
      integer, allocatable :: dlist(:)
      real(dp), allocatable :: amat(:, :), qv(:), lo(:), hi(:), z(:), wz(:)
      ! counts
      integer :: calls = 0          !! one-step problems solved
      integer :: patterns = 0       !! patterns solved (each a solve with a reduced factor and a check)
      integer :: fallbacks = 0      !! calls that needed the Lemke fallback
      integer :: lcp_largest = 0    !! most edges in doubt in a fallback
      real(dp) :: mismatch = 0.0_dp !! largest relative inconsistency of a group's residual met
      real(dp) :: tolw = 0.0_dp     !! velocity tolerance of the last check
   end type impulse_solver

contains

   !> Set up the solver for a structure (masses, springs) and its devices.
   subroutine solver_setup(p, mass, si, sj, sk, dev_i, dev_j, pmu, error)
      type(impulse_solver), intent(out) :: p        !! the solver
      real(dp), intent(in) :: mass(:)               !! masses [kg]
      integer, intent(in) :: si(:), sj(:)           !! spring nodes (sj = 0: the table)
      real(dp), intent(in) :: sk(:)                 !! spring stiffness [N/m]
      integer, intent(in) :: dev_i(:), dev_j(:)     !! device nodes (dev_j = 0: the table)
      real(dp), intent(in) :: pmu(:)                !! P mu of each device [N]
      type(error_type), allocatable, intent(out) :: error !! bad device nodes, workspace
      integer, allocatable :: inv(:), ei(:), ej(:)
      integer :: n, ne, i, kbw, stat

      n = size(mass)
      p%n = n
      call edges_setup(p%es, n, dev_i, dev_j, pmu, error)
      if (allocated(error)) return
      ne = p%es%ne
      p%ne = ne
      ! the nodes in RCM order of the graph of springs and edges: groups numbered in it
      allocate (p%node_order(n), inv(n), stat=stat)
      call allocation_error(error, stat, "the Moreau-Jean solver of n_dof = "//trim(fmt_int(n))//" DOFs")
      if (stat /= 0) return
      ei = [si, p%es%ei]
      ej = [sj, p%es%ej]
      call rcm_order(n, ei, ej, p%node_order)
      do i = 1, n
         inv(p%node_order(i)) = i
      end do
      kbw = graph_bandwidth(ei, ej, inv)
      call gs_setup(p%gs, mass, si, sj, sk, max(2*kbw, 8), error)
      if (allocated(error)) return
      allocate (p%sigma(ne), p%lam(ne), p%w(ne), p%locked(ne), p%fstuck(ne), &
                p%stuck(ne), p%changed(ne), p%viol(ne), p%doubt(ne), p%dlist(ne), &
                p%f(n), p%q(n), p%rho(0:n), p%sc(0:n), p%lsc(ne), p%col(n), p%rabs(n), &
                p%lam_prev(ne), p%w_prev(ne), p%sa(ne), p%fa(ne), p%amax(ne), p%queue(ne), p%wt(ne), stat=stat)
      call allocation_error(error, stat, "the Moreau-Jean solver of n_dof = "//trim(fmt_int(n))//" DOFs")
      if (stat /= 0) return
      do i = 1, ne
         p%amax(i) = 1.0_dp/mass(p%es%ei(i))
         if (p%es%ej(i) > 0) p%amax(i) = p%amax(i) + 1.0_dp/mass(p%es%ej(i))
      end do
      p%sigma = 0
      p%lam = 0.0_dp
      p%w = 0.0_dp
      p%locked = .false.
      p%fstuck = .false.
      p%changed = .false.
      p%viol = .false.
      p%doubt = .false.
      p%lsc = 0.0_dp
      p%pmax = min(ne, solver_max_lcp)
      if (p%pmax > 0) then
         call lcp_init(p%lcp, p%pmax, p%pmax, error)
         if (allocated(error)) return
      end if
      allocate (p%amat(p%pmax, p%pmax), p%qv(p%pmax), p%lo(p%pmax), p%hi(p%pmax), p%z(p%pmax), p%wz(p%pmax), &
                stat=stat)
      call allocation_error(error, stat, "the Moreau-Jean solver of n_dof = "//trim(fmt_int(n))//" DOFs")
   end subroutine solver_setup

   !> Solve the one-step problem W v1 = r - B lambda with the complementarity conditions
   !> (module header), from the pattern in p%sigma (the previous solution: warm start). On
   !> exit p%sigma, p%lam and p%w hold the solution's pattern, impulses and end velocities.
   subroutine solve_impulses(p, r, rabs, alpha, beta, g, v1, error)
      type(impulse_solver), intent(inout) :: p      !! the solver
      real(dp), intent(in) :: r(:)                  !! free right-hand side (n)
      real(dp), intent(in) :: rabs(:)               !! size of the terms r was summed from (n, >= |r|),
                                                    !! for the tolerances of the checks
      real(dp), intent(in) :: alpha                 !! W = alpha M + beta K: alpha > 0
      real(dp), intent(in) :: beta                  !! and beta >= 0
      real(dp), intent(in) :: g(:)                  !! (ne) bounds of the impulses, > 0
      real(dp), intent(out) :: v1(:)                !! end-of-step velocities (n)
      type(error_type), allocatable, intent(out) :: error !! singular system, LCP failure
      logical :: done

      p%calls = p%calls + 1
      p%changed = .false.
      p%viol = .false.
      p%rabs = rabs
      call active_set(p, r, alpha, beta, g, v1, merge(p%max_iter, 2*p%ne + 50, p%max_iter > 0), done, error)
      if (allocated(error) .or. done) return
      call fallback(p, r, alpha, beta, g, v1, error)
   end subroutine solve_impulses

   !> The active-set (block principal pivoting) iteration from the pattern p%sigma, at most
   !> max_it patterns: all violating edges change while their number falls (or for
   !> max_backups tries more), then the last one alone.
   subroutine active_set(p, r, alpha, beta, g, v1, max_it, done, error)
      type(impulse_solver), intent(inout) :: p
      real(dp), intent(in) :: r(:), alpha, beta, g(:)
      real(dp), intent(out) :: v1(:)
      integer, intent(in) :: max_it
      logical, intent(out) :: done
      type(error_type), allocatable, intent(out) :: error
      integer :: it, nviol, last, best, backups, e

      done = .false.
      best = huge(1)
      backups = max_backups
      do it = 1, max_it
         call solve_pattern(p, r, alpha, beta, g, v1, error)
         if (allocated(error)) return
         call check_pattern(p, alpha, beta, g, v1, nviol, last)
         if (nviol == 0) then
            call finish(p, g)
            done = .true.
            return
         end if
         if (nviol < best .or. backups > 0) then
            if (nviol < best) then
               best = nviol
               backups = max_backups
            else
               backups = backups - 1
            end if
            call expand_stops(p)
            do e = 1, p%ne
               if (p%viol(e)) call flip(p, e)
            end do
         else
            call flip(p, last)
         end if
      end do
   end subroutine active_set

   !> Devices that stop together. A sliding edge found moving the wrong way is to stop: the
   !> impulse that stops it, d_e = w_e / (b_e'W^-1 b_e), changes the relative velocity of
   !> every edge sharing a node x with it by -(b_f(x) b_e(x) / m_x) d_e / (b_e'M^-1 b_e)
   !> (W taken as its mass part alpha M, which dominates it at a step's scale). A sliding
   !> neighbour thereby turned the wrong way (beyond the tolerance) is to stop too, and so on
   !> along the structure. A sliding edge cannot see that its neighbour stops before the
   !> neighbour has stopped: without this estimate, a run of k devices stopping at once
   !> (under proportional slip loads) takes k patterns. The estimate only proposes: the next
   !> pattern is checked exactly.
   subroutine expand_stops(p)
      type(impulse_solver), intent(inout) :: p
      integer :: head, tail, e, x, q, f, k
      real(dp) :: d

      tail = 0
      do e = 1, p%ne
         p%wt(e) = p%w(e)
         if (p%viol(e) .and. .not. p%stuck(e) .and. .not. p%locked(e)) then
            tail = tail + 1
            p%queue(tail) = e
         end if
      end do
      head = 1
      do while (head <= tail)
         e = p%queue(head)
         head = head + 1
         d = p%wt(e)/p%amax(e)
         p%wt(e) = 0.0_dp
         do k = 1, 2
            x = merge(p%es%ei(e), p%es%ej(e), k == 1)
            if (x == 0) cycle
            do q = p%es%start(x), p%es%start(x + 1) - 1
               f = p%es%inc(q)
               if (f == e .or. p%stuck(f) .or. p%locked(f) .or. p%doubt(f)) cycle
               ! b_f(x) b_e(x) = +1 when x is the same end of both edges, -1 otherwise
               if ((p%es%ei(f) == x) .eqv. (p%es%ei(e) == x)) then
                  p%wt(f) = p%wt(f) - d/p%gs%mass(x)
               else
                  p%wt(f) = p%wt(f) + d/p%gs%mass(x)
               end if
               if (p%viol(f)) cycle
               if (p%sigma(f)*p%wt(f) < -p%tolw) then
                  p%viol(f) = .true.
                  tail = tail + 1
                  p%queue(tail) = f
               end if
            end do
         end do
      end do
   end subroutine expand_stops

   !> The acceleration of the structure at the end of a step: nodal forces f (all but
   !> friction) and Coulomb's law at the level of accelerations, given the end velocities:
   !> a device that slides keeps sigma P mu; one at rest (sticking at the end of the step)
   !> holds if the force that keeps it at rest is within P mu, else it starts to slide in
   !> the direction of that force (as the exact technique decides at an event). The groups'
   !> masses are diagonal, so a pattern's acceleration a = T (T'M T)^-1 T'(f - B_L F_L) and
   !> its sticking forces (elimination over the groups' trees) cost a few passes over the
   !> nodes and no factorization; the pattern of the step is the first guess, and in most
   !> steps the answer.
   subroutine pattern_acceleration(p, f, pmu, acc)
      type(impulse_solver), intent(inout) :: p      !! the solver, after a solve_impulses
      real(dp), intent(in) :: f(:)                  !! nodal forces but friction [N] (n)
      real(dp), intent(in) :: pmu(:)                !! (ne) P mu of each edge [N]
      real(dp), intent(out) :: acc(:)               !! accelerations [m/s2] (n)
      real(dp) :: mm, tola
      integer :: e, i, it, nviol

      p%sa = p%sigma
      do it = 1, p%ne + 2
         p%stuck = p%sa == 0
         if (.not. all(p%stuck .eqv. p%fstuck)) then
            ! the groups of this pattern (the factor's are then rebuilt at the next step)
            call groups_build(p%es, p%stuck, p%node_order)
            p%fvalid = .false.
         end if
         p%col = f
         p%sc(1:p%n) = abs(f)
         do e = 1, p%ne
            if (p%stuck(e)) cycle
            call add_edge(p%es, e, -p%sa(e)*pmu(e), p%col)
            p%sc(p%es%ei(e)) = p%sc(p%es%ei(e)) + pmu(e)
            p%sc(p%es%ej(e)) = p%sc(p%es%ej(e)) + pmu(e)
         end do
         call restrict(p%es, p%col, p%q)
         call restrict(p%es, p%gs%mass, p%f)
         do i = 1, p%es%nr
            p%q(i) = p%q(i)/p%f(i)
         end do
         call expand(p%es, p%q, acc)
         ! the forces that keep the sticking devices at rest: B_S F_S = f - B_L F_L - M a
         p%rho(0) = 0.0_dp
         p%sc(0) = 0.0_dp
         p%rho(1:p%n) = p%col - p%gs%mass*acc
         tola = tol_rel*maxval(p%sc(1:p%n)/p%gs%mass) + tiny(1.0_dp)
         call recover_impulses(p%es, p%stuck, p%rho, p%sc, p%fa, p%lsc, mm)
         nviol = 0
         do e = 1, p%ne
            if (p%stuck(e)) then
               if (abs(p%fa(e)) > pmu(e) + tol_rel*p%lsc(e)) then
                  p%sa(e) = merge(1, -1, p%fa(e) > 0.0_dp)
                  nviol = nviol + 1
               end if
            else if (p%sigma(e) == 0) then
               ! started at the end of the step: it must accelerate its way
               if (p%sa(e)*edge_relative(p%es, e, acc) < -tola) then
                  p%sa(e) = 0
                  nviol = nviol + 1
               end if
            end if
         end do
         if (nviol == 0) return
      end do
   end subroutine pattern_acceleration

   !> The first guess of the next step's pattern: the last solution's, except where the trend
   !> of the last two solutions (same step size) crosses a limit within the step: a sliding
   !> edge whose relative velocity, extrapolated linearly, changes sign is guessed sticking, a
   !> sticking edge whose impulse, extrapolated, leaves its bound is guessed sliding that way.
   !> Devices that stop together (proportional slip loads) are then guessed together, where
   !> the active-set iteration would find them one after the other (a sliding device cannot
   !> see that its neighbours stop).
   pure subroutine predict_pattern(p, g)
      type(impulse_solver), intent(inout) :: p      !! the solver, after a solve_impulses
      real(dp), intent(in) :: g(:)                  !! (ne) bounds of the next step's impulses
      real(dp) :: x
      integer :: e

      if (p%have_prev) then
         ! a change only where the trend crosses the limit by more than the tolerances of the
         ! checks: a device at rest at its limit (both statuses hold) keeps its status
         do e = 1, p%ne
            if (p%locked(e)) cycle
            if (p%sigma(e) == 0) then
               x = 2.0_dp*p%lam(e) - p%lam_prev(e)
               if (abs(x) > g(e) + tol_rel*p%lsc(e)) p%sigma(e) = merge(1, -1, x > 0.0_dp)
            else
               x = 2.0_dp*p%w(e) - p%w_prev(e)
               if (p%sigma(e)*x < -p%tolw) p%sigma(e) = 0
            end if
         end do
      end if
      p%lam_prev = p%lam
      p%w_prev = p%w
      p%have_prev = .true.
   end subroutine predict_pattern

   !> Change the status of edge e: sticking to sliding in the direction of its impulse,
   !> sliding to sticking.
   pure subroutine flip(p, e)
      type(impulse_solver), intent(inout) :: p
      integer, intent(in) :: e

      if (p%sigma(e) == 0) then
         p%sigma(e) = merge(1, -1, p%lam(e) > 0.0_dp)
      else
         p%sigma(e) = 0
      end if
      p%changed(e) = .true.
   end subroutine flip

   !> Factor the reduced system of the sticking edges p%stuck unless it is the current one.
   subroutine ensure_factor(p, alpha, beta, error)
      type(impulse_solver), intent(inout) :: p
      real(dp), intent(in) :: alpha, beta
      type(error_type), allocatable, intent(out) :: error

      if (p%fvalid .and. alpha == p%falpha .and. beta == p%fbeta) then
         if (all(p%stuck .eqv. p%fstuck)) return
      end if
      p%fvalid = .false.
      call groups_build(p%es, p%stuck, p%node_order)
      call gs_factor(p%gs, p%es%grp, p%es%nr, alpha, beta, error)
      if (allocated(error)) return
      p%fstuck = p%stuck
      p%falpha = alpha
      p%fbeta = beta
      p%fvalid = .true.
   end subroutine ensure_factor

   !> v1 = T (T'W T)^-1 T' f for the current factor.
   subroutine reduced_solve(p, f, v1)
      type(impulse_solver), intent(inout) :: p
      real(dp), intent(in) :: f(:)
      real(dp), intent(out) :: v1(:)

      call restrict(p%es, f, p%q)
      call gs_solve(p%gs, p%q)
      call expand(p%es, p%q, v1)
   end subroutine reduced_solve

   !> The solution of the pattern p%sigma: f = r - sum over sliding edges of sigma g b, v1.
   subroutine solve_pattern(p, r, alpha, beta, g, v1, error)
      type(impulse_solver), intent(inout) :: p
      real(dp), intent(in) :: r(:), alpha, beta, g(:)
      real(dp), intent(out) :: v1(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: e

      p%stuck = p%sigma == 0
      call ensure_factor(p, alpha, beta, error)
      if (allocated(error)) return
      p%f = r
      do e = 1, p%ne
         if (p%stuck(e)) cycle
         p%lam(e) = p%sigma(e)*g(e)
         call add_edge(p%es, e, -p%lam(e), p%f)
      end do
      call reduced_solve(p, p%f, v1)
      p%patterns = p%patterns + 1
   end subroutine solve_pattern

   !> Check a pattern's solution: the sliding edges (not in doubt, not locked) must move their
   !> way, the sticking ones' impulses (recovered from rho = f - W v1) be within bounds. Sets
   !> p%w, the impulses of the sticking edges, p%viol; last = the last violating edge.
   subroutine check_pattern(p, alpha, beta, g, v1, nviol, last)
      type(impulse_solver), intent(inout) :: p
      real(dp), intent(in) :: alpha, beta, g(:), v1(:)
      integer, intent(out) :: nviol, last
      real(dp) :: tolw, mm
      integer :: e, n

      n = p%n
      ! the size of the terms of rho = f - W v1 (f: r and the sliding impulses), for the
      ! tolerances: of the impulses below, of the velocities (that size over alpha M)
      p%rho(0) = 0.0_dp
      p%sc(0) = 0.0_dp
      p%rho(1:n) = p%f - alpha*p%gs%mass*v1
      call gs_k_matvec(p%gs, v1, p%rho(1:n), -beta, 1.0_dp)
      p%sc(1:n) = p%rabs + alpha*p%gs%mass*abs(v1)
      call gs_k_absmatvec(p%gs, v1, p%sc(1:n), beta)
      do e = 1, p%ne
         if (p%stuck(e)) cycle
         p%sc(p%es%ei(e)) = p%sc(p%es%ei(e)) + abs(p%lam(e))
         p%sc(p%es%ej(e)) = p%sc(p%es%ej(e)) + abs(p%lam(e))
      end do
      tolw = tol_rel*maxval(p%sc(1:n)/(alpha*p%gs%mass)) + tiny(1.0_dp)
      p%viol = .false.
      do e = 1, p%ne
         p%w(e) = edge_relative(p%es, e, v1)
         if (p%stuck(e) .or. p%locked(e) .or. p%doubt(e)) cycle
         if (p%sigma(e)*p%w(e) < -tolw) p%viol(e) = .true.
      end do
      p%tolw = tolw
      ! impulses of the sticking edges: B_S lambda_S = f - W v1
      call recover_impulses(p%es, p%stuck, p%rho, p%sc, p%lam, p%lsc, mm)
      p%mismatch = max(p%mismatch, mm)
      do e = 1, p%ne
         if (.not. p%stuck(e)) cycle
         if (abs(p%lam(e)) > g(e) + tol_rel*p%lsc(e)) p%viol(e) = .true.
      end do
      nviol = count(p%viol)
      last = 0
      do e = p%ne, 1, -1
         if (p%viol(e)) then
            last = e
            exit
         end if
      end do
   end subroutine check_pattern

   !> The pattern solved: impulses of the sliding edges at their limits.
   pure subroutine finish(p, g)
      type(impulse_solver), intent(inout) :: p
      real(dp), intent(in) :: g(:)
      integer :: e

      do e = 1, p%ne
         if (.not. p%stuck(e)) p%lam(e) = p%sigma(e)*g(e)
      end do
   end subroutine finish

   !> Lemke's method on the edges in doubt, the others keeping their status, until every
   !> edge satisfies its conditions (module header).
   subroutine fallback(p, r, alpha, beta, g, v1, error)
      type(impulse_solver), intent(inout) :: p
      real(dp), intent(in) :: r(:), alpha, beta, g(:)
      real(dp), intent(out) :: v1(:)
      type(error_type), allocatable, intent(out) :: error
      type(lcp_info) :: info
      integer :: nd, e, k, j, round, nviol, last
      real(dp) :: tolw

      p%fallbacks = p%fallbacks + 1
      p%doubt = (p%changed .or. p%viol) .and. .not. p%locked
      do round = 1, p%ne + 1
         nd = 0
         do e = 1, p%ne
            if (.not. p%doubt(e)) cycle
            nd = nd + 1
            p%dlist(nd) = e
         end do
         p%lcp_largest = max(p%lcp_largest, nd)
         if (nd > p%pmax) then
            call fatal_error(error, "moreau_jean: the one-step problem needs Lemke's method on "// &
                             trim(fmt_int(nd))//" devices in doubt, more than its capacity "// &
                             trim(fmt_int(p%pmax))//" (the active-set iteration did not settle)")
            p%doubt = .false.
            return
         end if
         ! the others keep their status; the edges in doubt are free (their impulses unknown)
         p%stuck = p%sigma == 0 .and. .not. p%doubt
         call ensure_factor(p, alpha, beta, error)
         if (allocated(error)) return
         p%f = r
         do e = 1, p%ne
            if (p%stuck(e) .or. p%doubt(e)) cycle
            p%lam(e) = p%sigma(e)*g(e)
            call add_edge(p%es, e, -p%lam(e), p%f)
         end do
         call reduced_solve(p, p%f, v1)
         ! Delassus operator of the edges in doubt and their free velocities
         do k = 1, nd
            p%qv(k) = -edge_relative(p%es, p%dlist(k), v1)
            p%col = 0.0_dp
            call add_edge(p%es, p%dlist(k), 1.0_dp, p%col)
            call reduced_solve(p, p%col, p%rho(1:p%n))
            do j = 1, nd
               p%amat(j, k) = edge_relative(p%es, p%dlist(j), p%rho(1:p%n))
            end do
            p%lo(k) = -g(p%dlist(k))
            p%hi(k) = g(p%dlist(k))
         end do
         ! w_box = A z - w_free = -w: z at hi needs w >= 0, at lo w <= 0
         if (nd > 0) call box_lcp_solve(p%lcp, p%amat(1:nd, 1:nd), p%qv(1:nd), p%lo(1:nd), p%hi(1:nd), &
                                        p%z(1:nd), p%wz(1:nd), info)
         if (nd > 0 .and. info%status /= lcp_solved) then
            call fatal_error(error, "moreau_jean: Lemke's method failed on the one-step problem of "// &
                             trim(fmt_int(nd))//" devices in doubt: "//trim(lcp_status_text(info%status)))
            p%doubt = .false.
            return
         end if
         do k = 1, nd
            e = p%dlist(k)
            p%lam(e) = p%z(k)
            call add_edge(p%es, e, -p%z(k), p%f)
         end do
         call reduced_solve(p, p%f, v1)
         p%patterns = p%patterns + 1
         call check_pattern(p, alpha, beta, g, v1, nviol, last)
         if (nviol == 0) exit
         ! the violated edges join D; a violated sticking edge in a group with a loop brings
         ! the group's sticking edges (its impulses are not unique)
         do e = 1, p%ne
            if (.not. p%viol(e)) cycle
            p%doubt(e) = .true.
            if (p%stuck(e)) then
               if (p%es%loops(p%es%grp(p%es%ei(e)))) then
                  do j = 1, p%ne
                     if (p%stuck(j)) then
                        if (p%es%grp(p%es%ei(j)) == p%es%grp(p%es%ei(e))) p%doubt(j) = .true.
                     end if
                  end do
               end if
            end if
         end do
      end do
      ! the edges in doubt: sticking when their end velocity is zero, else sliding their way
      tolw = p%tolw
      do e = 1, p%ne
         if (p%doubt(e)) then
            if (abs(p%w(e)) <= tolw) then
               p%sigma(e) = 0
            else
               p%sigma(e) = merge(1, -1, p%w(e) > 0.0_dp)
            end if
         else if (.not. p%stuck(e)) then
            p%lam(e) = p%sigma(e)*g(e)
         end if
      end do
      p%doubt = .false.
   end subroutine fallback

end module fd_impulse_solver
