!> The phase decision of the exact technique at an instant: which devices stick, which
!> slide and which way, from the linear complementarity problems of the instant
!> (docs/theory.md, section 9).
!>
!> **Level 0 (accelerations).** The candidates are the sticking devices and the sliding
!> ones at zero relative velocity; every other device slides on with F = sgn P mu. With
!> p the forces on the structure but the candidates' friction (table inertia, springs,
!> dampers, the other sliders), the candidates' relative accelerations are
!> s'' = B'M^-1 p - W F, W = B'M^-1 B (M diagonal: W is formed directly), and Coulomb's
!> law is the box LCP (fd_lcp): z = F in [-P mu, P mu], w = -s'' = W z - B'M^-1 p. Its w
!> is unique (W symmetric positive semidefinite); a candidate with w < 0 slides +, with
!> w > 0 slides -, with w = 0 (to its rounding tolerance) holds at this order. The
!> holding ones stick with the forces of their pattern's force map (fd_phase_pattern);
!> those whose force is at its limit are degenerate: sticking and sliding give the same
!> acceleration, and the next derivative decides.
!>
!> **Levels L = 1, 2, 3 (the next derivatives).** Let D be the degenerate devices, sgn_d
!> the sign of their force. In the pattern P1 in which they slide with F = sgn P mu (the
!> other holders stick), their relative motion starts with s' = s'' = 0; if the lower
!> levels were degenerate too, the first nonzero term of s'' is of order L. A device of D
!> that sticks instead changes its force by dF = f_L tau^L, which changes s'' by
!> -W1 dF at that order (W1: the Delassus operator of D in P1). Coulomb's law at order L
!> is the standard LCP
!>   r = q_L + diag(sgn) W1 diag(sgn) y,  y >= 0, r >= 0, y'r = 0,
!> y = -sgn f_L (the force falls from its limit), r = sgn s^(L+2) (the device moves its
!> way), q_L = sgn s^(L+2) of P1. r > 0: slides; y > 0: sticks; both 0: the next level.
!>
!> **Undecided at level 3.** A device whose derivatives vanish to the rounding level to
!> order 5 is at a tie (e.g. a storey whose force stays at its limit while the storey
!> below slides): it keeps its phase, unless its own event function crossed its band,
!> the sign that its force (or velocity) has left the limit (or zero): then it changes
!> phase. Either way the choice is exact to the rounding level, and a wrong one is
!> corrected at the next event (the event function leaves its band again).
!>
!> **Redundant devices** (in parallel, in a closed loop of sticking devices): the forces
!> of the pattern share the load in proportion to the limits; where that share exceeds a
!> limit while the LCP's forces do not, the share of least max |F_d| / (P mu_d) with the
!> same resultant is kept (a constant in the null space of the incidence, found by
!> bisection on box LCPs of shrunk bounds) until the next event: every force then has the
!> widest margin to its limit that the loop allows. (The LCP's own share is a vertex of
!> the box: a force on its limit, which crosses it again at once when the pattern's share
!> grows beyond it; the same decision then came back every 1e-13 s, a run without end.)
module fd_phase_decision
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real
   use fd_model, only: model_type
   use fd_excitation, only: excitation_type, table_motion, table_taylor
   use fd_kinematics, only: device_relative, add_device, add_device_abs, pair_nodes, device_coupling, &
                            device_inverse_mass_relative, device_abs_inverse_mass_relative
   use fd_device_state, only: phase_stick
   use fd_lcp, only: box_lcp_solve, lcp_solve, lcp_info, lcp_solved, lcp_status_text
   use fd_phase_pattern, only: cache_find, pattern_entry, pattern_taylor
   use fd_ed_state, only: ed_state
   implicit none
   private

   public :: decide_phases, device_list, rtol_decision, max_level

   real(dp), parameter :: rtol_decision = 1.0e-11_dp  !! zero, relative to the magnitude of the terms
   integer, parameter :: max_level = 3                !! highest derivative level of the decision

   !> What one decision carries from step to step.
   type :: decision_type
      real(dp) :: t = 0.0_dp      !! the instant [s]
      real(dp) :: ag = 0.0_dp     !! the table acceleration then [m/s2]
      integer :: nc = 0           !! candidates of level 0
      integer :: ndg = 0          !! degenerate devices still undecided
      integer :: slot0 = 0        !! the level-0 pattern's slot
      integer :: slot1 = 0        !! the current pattern's slot (derivative levels, then the new one)
   end type decision_type

contains

   !> Decide the phases at time t from the state st%u, st%v and the phases before
   !> (st%phase); st%near flags the sliding devices at zero relative velocity (to their
   !> tolerance) and st%crossed the devices whose event function has crossed its band.
   !> On return st%phase, st%cur and the entry data (q, p, uc, b1, f0) are those of the
   !> new pattern, v is projected on its constraints, and `changed` tells whether any
   !> phase changed. The steps are those of the module's description, in order.
   subroutine decide_phases(model, exc, t, st, changed, error)
      type(model_type), intent(in) :: model         !! the model
      type(excitation_type), intent(in) :: exc      !! the table motion
      real(dp), intent(in) :: t                     !! time [s]
      type(ed_state), intent(inout) :: st           !! the state
      logical, intent(out) :: changed               !! some phase changed
      type(error_type), allocatable, intent(out) :: error !! a complementarity problem unsolved
      type(decision_type) :: dc
      real(dp) :: xg, vg

      changed = .false.
      dc%t = t
      call table_motion(exc, t, xg, vg, dc%ag)
      st%oldph = st%phase
      st%newph = st%phase
      call list_candidates(st, dc%nc)
      if (dc%nc > 0) then
         call decide_accelerations(model, st, dc, error)
         if (allocated(error)) return
      end if
      call enter(model, exc, st, dc, st%newph, 0, error)
      if (allocated(error)) return
      call list_degenerate(st, dc)
      dc%slot1 = dc%slot0
      call decide_derivatives(model, exc, st, dc, error)
      if (allocated(error)) return
      call settle_ties(st, dc%ndg)
      call enter(model, exc, st, dc, st%newph, 1, error)
      if (allocated(error)) return
      st%cur = dc%slot1
      st%phase = st%newph
      changed = any(st%phase /= st%oldph)
      if (dc%nc > 0) call share_redundant_forces(model, st, dc)
   end subroutine decide_phases

   !> The candidates of level 0 (st%cand(1:nc)): the sticking devices and the sliding ones
   !> at zero relative velocity; a device without friction (P mu = 0) sticks in name only.
   pure subroutine list_candidates(st, nc)
      type(ed_state), intent(inout) :: st     !! the state
      integer, intent(out) :: nc              !! how many
      integer :: d

      nc = 0
      do d = 1, st%nd
         if (.not. st%active(d)) then
            st%newph(d) = phase_stick
            cycle
         end if
         if (st%phase(d) == phase_stick .or. st%near(d)) then
            nc = nc + 1
            st%cand(nc) = d
         end if
      end do
   end subroutine list_candidates

   !> Level 0: the box LCP of the candidates' accelerations. A candidate with w < 0 slides
   !> +, with w > 0 slides -, with w = 0 (to its tolerance) holds at this order (sticks, for
   !> now); its force is kept in st%zs.
   subroutine decide_accelerations(model, st, dc, error)
      type(model_type), intent(in) :: model         !! the model
      type(ed_state), intent(inout) :: st           !! the state, st%cand(1:dc%nc) the candidates
      type(decision_type), intent(in) :: dc         !! the decision so far
      type(error_type), allocatable, intent(out) :: error !! the LCP unsolved, forces not finite
      type(lcp_info) :: info
      real(dp) :: sc
      integer :: a, b, d, i, j, nc

      nc = dc%nc
      ! p = -M r ag - C v - K u - sum_(other sliders) b sgn P mu, and its magnitude
      do i = 1, st%n
         st%pe(i) = -st%mass(i)*st%rinf(i)*dc%ag
         st%pa(i) = abs(st%mass(i)*st%rinf(i)*dc%ag)
      end do
      do j = 1, st%n
         do i = 1, st%n
            st%pe(i) = st%pe(i) - st%c(i, j)*st%v(j) - st%k(i, j)*st%u(j)
            st%pa(i) = st%pa(i) + abs(st%c(i, j)*st%v(j)) + abs(st%k(i, j)*st%u(j))
         end do
      end do
      do d = 1, st%nd
         if (.not. st%active(d) .or. st%phase(d) == phase_stick .or. st%near(d)) cycle
         call add_device(model, d, -st%phase(d)*st%slip(d), st%pe)
         call add_device_abs(model, d, st%slip(d), st%pa)
      end do
      if (.not. all(ieee_is_finite(st%pe))) then
         call fatal_error(error, "event-driven technique at t = "//trim(fmt_real(dc%t))//" s: the forces on "// &
                          "the structure are not finite (an overflow); check the masses, the stiffnesses, "// &
                          "the initial displacements u0 and velocities v0, and the table motion")
         return
      end if
      do a = 1, nc
         st%lq(a) = -device_inverse_mass_relative(model, st%cand(a), st%pe)
         st%lqa(a) = device_abs_inverse_mass_relative(model, st%cand(a), st%pa)
         do b = 1, nc
            st%wm(a, b) = device_coupling(model, st%cand(a), st%cand(b))
         end do
         st%lo(a) = -st%slip(st%cand(a))
         st%hi(a) = st%slip(st%cand(a))
      end do
      call box_lcp_solve(st%lcp, st%wm(1:nc, 1:nc), st%lq(1:nc), st%lo(1:nc), st%hi(1:nc), st%z(1:nc), &
                         st%w(1:nc), info)
      if (info%status /= lcp_solved) then
         call lcp_failed("the box LCP of the accelerations", nc, st%cand, info, dc%t, error)
         return
      end if
      do a = 1, nc
         d = st%cand(a)
         st%zs(d) = st%z(a)
         sc = st%lqa(a)
         do b = 1, nc
            sc = sc + abs(st%wm(a, b)*st%z(b))
         end do
         if (st%w(a) < -rtol_decision*sc) then
            st%newph(d) = 1
         else if (st%w(a) > rtol_decision*sc) then
            st%newph(d) = -1
         else
            st%newph(d) = phase_stick
         end if
      end do
   end subroutine decide_accelerations

   !> The degenerate devices of the level-0 pattern (entered in dc%slot0): those that stick
   !> with a force at its limit, in st%cand(1:dc%ndg) with the force's sign in st%sig.
   pure subroutine list_degenerate(st, dc)
      type(ed_state), intent(inout) :: st           !! the state, the level-0 pattern entered
      type(decision_type), intent(inout) :: dc      !! the decision so far
      real(dp) :: f, fa
      integer :: r, d

      dc%ndg = 0
      associate (pat => st%cache%slot(dc%slot0))
         do r = 1, pat%ns
            d = pat%ids(r)
            call force_now(st, dc%slot0, r, dc%ag, f, fa)
            if (abs(f) >= st%slip(d) - rtol_decision*(fa + st%slip(d))) then
               dc%ndg = dc%ndg + 1
               st%cand(dc%ndg) = d
               st%sig(dc%ndg) = int(sign(1.0_dp, f))
            end if
         end do
      end associate
   end subroutine list_degenerate

   !> Levels 1..max_level: the LCP of the next derivative of the degenerate devices, in the
   !> pattern in which they slide their force's way (dc%slot1). r > 0 slides, y > 0 sticks;
   !> the devices with both 0 go on to the next level (st%cand(1:dc%ndg) on return: those
   !> still undecided after the last).
   subroutine decide_derivatives(model, exc, st, dc, error)
      type(model_type), intent(in) :: model         !! the model
      type(excitation_type), intent(in) :: exc      !! the table motion
      type(ed_state), intent(inout) :: st           !! the state
      type(decision_type), intent(inout) :: dc      !! the decision so far
      type(error_type), allocatable, intent(out) :: error !! an LCP unsolved
      type(lcp_info) :: info
      real(dp) :: sc
      integer :: a, b, d, i, lev, gi, gj, kk, ni, nj

      do lev = 1, max_level
         if (dc%ndg == 0) exit
         do a = 1, dc%ndg
            st%newph(st%cand(a)) = st%sig(a)
         end do
         call enter(model, exc, st, dc, st%newph, 1, error)
         if (allocated(error)) return
         associate (pat => st%cache%slot(dc%slot1))
            kk = lev + 2
            call table_taylor(exc, dc%t, st%g(0:kk), st%gn(0:kk))
            call pattern_taylor(pat, st%q, st%p, st%b1, st%g(0:kk), st%qc, st%pc, st%cp)
            call abs_taylor(st, dc%slot1, lev + 2)
            do a = 1, dc%ndg
               d = st%cand(a)
               if (pat%general) then
                  call general_level(st, dc%slot1, a, lev, dc%ndg)
                  cycle
               end if
               call pair_nodes(model, d, ni, nj)
               gi = pat%grp(ni)
               gj = 0
               if (nj > 0) gj = pat%grp(nj)
               st%lq(a) = 0.0_dp
               st%lqa(a) = 0.0_dp
               if (gi > 0) then
                  st%lq(a) = st%qc(gi, lev + 2)
                  st%lqa(a) = st%qa(gi, lev + 2)
               end if
               if (gj > 0) then
                  st%lq(a) = st%lq(a) - st%qc(gj, lev + 2)
                  st%lqa(a) = st%lqa(a) + st%qa(gj, lev + 2)
               end if
               st%lq(a) = st%sig(a)*st%lq(a)
               do b = 1, dc%ndg
                  st%wm(a, b) = st%sig(a)*st%sig(b)*group_delassus(model, st%cand(a), st%cand(b), pat%grp, pat%mq)
               end do
            end do
         end associate
         call lcp_solve(st%lcp, st%wm(1:dc%ndg, 1:dc%ndg), st%lq(1:dc%ndg), st%z(1:dc%ndg), st%w(1:dc%ndg), info)
         if (info%status /= lcp_solved) then
            call lcp_failed("the LCP of derivative level "//trim(fmt_int(lev)), dc%ndg, st%cand, info, dc%t, error)
            return
         end if
         ! decided: r > 0 slides, y > 0 sticks; the others go to the next level
         b = 0
         do a = 1, dc%ndg
            d = st%cand(a)
            sc = st%lqa(a)
            do i = 1, dc%ndg
               sc = sc + abs(st%wm(a, i)*st%z(i))
            end do
            if (st%w(a) > rtol_decision*sc) then
               st%newph(d) = st%sig(a)
            else if (st%z(a)*st%wm(a, a) > rtol_decision*sc) then
               st%newph(d) = phase_stick
            else
               st%newph(d) = phase_stick
               b = b + 1
               st%cand(b) = d
               st%sig(b) = st%sig(a)
            end if
         end do
         dc%ndg = b
      end do
   end subroutine decide_derivatives

   !> Ties undecided at the last level (st%cand(1:ndg)): a device keeps its phase, unless
   !> its event function crossed its band (then it changes phase).
   pure subroutine settle_ties(st, ndg)
      type(ed_state), intent(inout) :: st     !! the state
      integer, intent(in) :: ndg              !! the undecided devices
      integer :: a, d

      do a = 1, ndg
         d = st%cand(a)
         if (st%crossed(d)) then
            if (st%oldph(d) == phase_stick) then
               st%newph(d) = st%sig(a)
            else
               st%newph(d) = phase_stick
            end if
         else if (st%oldph(d) == st%sig(a)) then
            st%newph(d) = st%sig(a)
         else
            st%newph(d) = phase_stick
         end if
      end do
   end subroutine settle_ties

   !> Redundant sticking devices of the new pattern (dc%slot1, entered): where the pattern's
   !> share of their load exceeds a limit, the share of least max |F_d| / (P mu_d) (a closed
   !> loop; least_ratio_share), else the level-0 LCP's share (st%zs).
   subroutine share_redundant_forces(model, st, dc)
      type(model_type), intent(in) :: model         !! the model
      type(ed_state), intent(inout) :: st           !! the state, the new pattern entered
      type(decision_type), intent(in) :: dc         !! the decision
      real(dp) :: f, fa
      integer :: r
      logical :: any_viol, centred

      associate (pat => st%cache%slot(dc%slot1))
         any_viol = .false.
         do r = 1, pat%ns
            call force_now(st, dc%slot1, r, dc%ag, f, fa)
            st%w(r) = f
            if (abs(f) > st%slip(pat%ids(r)) + rtol_decision*(fa + st%slip(pat%ids(r)))) any_viol = .true.
         end do
         if (any_viol) then
            centred = .false.
            if (pat%ns > st%n - pat%nq) call least_ratio_share(model, st, dc%slot1, centred)
            if (.not. centred) then
               do r = 1, pat%ns
                  st%f0(r) = st%f0(r) + (st%zs(pat%ids(r)) - st%w(r))
               end do
            end if
         end if
      end associate
   end subroutine share_redundant_forces

   !> Redundant sticking devices (more than the constraints they impose: a closed loop)
   !> whose share by the force map (st%w(1:ns)) exceeds a limit: the forces F with the
   !> same resultant B_S F and the least max |F_d| / (P mu_d), found by bisection on
   !> lambda of the box LCP z in [-lambda P mu, lambda P mu], w = W (z - F) (w = 0 iff
   !> B_S z = B_S F, W = B_S' M^-1 B_S); f0 takes the difference, projected on the null
   !> space of B_S (the motion does not change). Every force is then inside its limits
   !> by the widest margin the loop allows, so that the next crossing of a limit is a
   !> real event or at least a finite time away, not the same instant again (a vertex of
   !> the box, the LCP's share, sits on a limit and crosses it at once). done is false
   !> when no share within the limits was found (the caller keeps the LCP's).
   subroutine least_ratio_share(model, st, slot, done)
      type(model_type), intent(in) :: model   !! the model
      type(ed_state), intent(inout) :: st     !! the state, its pattern in slot entered
      integer, intent(in) :: slot             !! the pattern's slot
      logical, intent(out) :: done            !! a share within the limits was found
      real(dp), parameter :: lam_tol = 1.0e-9_dp   !! bisection's resolution of lambda
      real(dp), parameter :: w_tol = 1.0e-10_dp    !! w = 0, relative to its terms
      integer :: ns, aa, bb, it, ia, n
      real(dp) :: lam, lam_lo, lam_hi, scale
      logical :: feasible
      type(lcp_info) :: inf

      done = .false.
      n = st%n
      associate (pat => st%cache%slot(slot))
         ns = pat%ns
         ! the pattern's share F (lqa) and its resultant y = B_S F (pe)
         st%pe = 0.0_dp
         do aa = 1, ns
            st%lqa(aa) = st%w(aa)
            call add_device(model, pat%ids(aa), st%lqa(aa), st%pe)
         end do
         do aa = 1, ns
            st%lq(aa) = -device_inverse_mass_relative(model, pat%ids(aa), st%pe)
            do bb = 1, ns
               st%wm(aa, bb) = device_coupling(model, pat%ids(aa), pat%ids(bb))
            end do
         end do
         lam_lo = 0.0_dp
         lam_hi = 1.0_dp
         lam = 1.0_dp
         do it = 0, 60
            if (it > 0) lam = 0.5_dp*(lam_lo + lam_hi)
            do aa = 1, ns
               st%lo(aa) = -lam*st%slip(pat%ids(aa))
               st%hi(aa) = lam*st%slip(pat%ids(aa))
            end do
            call box_lcp_solve(st%lcp, st%wm(1:ns, 1:ns), st%lq(1:ns), st%lo(1:ns), st%hi(1:ns), st%z(1:ns), &
                               st%w(1:ns), inf)
            feasible = inf%status == lcp_solved
            if (feasible) then
               do aa = 1, ns
                  scale = 0.0_dp
                  do bb = 1, ns
                     scale = scale + abs(st%wm(aa, bb))*(abs(st%z(bb)) + abs(st%lqa(bb)))
                  end do
                  if (abs(st%w(aa)) > w_tol*scale) feasible = .false.
               end do
            end if
            if (feasible) then
               lam_hi = lam
               st%zs(1:ns) = st%z(1:ns)
               done = .true.
            else
               if (it == 0) exit
               lam_lo = lam
            end if
            if (lam_hi - lam_lo <= lam_tol) exit
         end do
         if (.not. done) then
            st%w(1:ns) = st%lqa(1:ns)   ! the pattern's share, for the caller
            return
         end if
         ! the difference, projected on the null space of B_S: c - D (B_S D)^+ B_S c
         st%pe = 0.0_dp
         do aa = 1, ns
            st%zs(aa) = st%zs(aa) - st%lqa(aa)
            call add_device(model, pat%ids(aa), st%zs(aa), st%pe)
         end do
         do aa = 1, ns
            scale = st%zs(aa)
            do ia = 1, n
               scale = scale - pat%pinv(aa, ia)*st%pe(ia)
            end do
            st%f0(aa) = st%f0(aa) + scale
         end do
      end associate
   end subroutine least_ratio_share

   !> Find (or build) the pattern of the phases ph and enter it at the state; it becomes the
   !> decision's level-0 pattern (which = 0, dc%slot0) or its current one (which = 1,
   !> dc%slot1). The patterns in use (st%cur, dc%slot0, dc%slot1) are not replaced.
   subroutine enter(model, exc, st, dc, ph, which, err)
      type(model_type), intent(in) :: model         !! the model
      type(excitation_type), intent(in) :: exc      !! the table motion
      type(ed_state), intent(inout) :: st           !! the state
      type(decision_type), intent(inout) :: dc      !! the decision so far
      integer, intent(in) :: ph(:)                  !! the phases
      integer, intent(in) :: which                  !! 0: slot0, 1: slot1
      type(error_type), allocatable, intent(out) :: err !! the pattern could not be built
      integer :: slot, pinned(3)

      pinned = [st%cur, dc%slot0, dc%slot1]
      call cache_find(st%cache, model, st%mass, st%k, st%c, st%active, ph, st%slip, exc, pinned, slot, err)
      if (allocated(err)) then
         err%message = "event-driven technique at t = "//trim(fmt_real(dc%t))//" s: "//err%message
         return
      end if
      if (which == 0) then
         dc%slot0 = slot
      else
         dc%slot1 = slot
      end if
      call pattern_entry(st%cache%slot(slot), model, st%mass, st%k, ph, st%slip, st%u, st%v, st%q, st%p, &
                         st%uc, st%b1, st%f0, st%fn)
   end subroutine enter

   !> The force of the r-th sticking device of the pattern in slot (the one entered
   !> last) now, and the magnitude of its terms.
   pure subroutine force_now(st, slot, r, agt, fr, fabs)
      type(ed_state), intent(in) :: st        !! the state, the pattern in slot entered
      integer, intent(in) :: slot, r          !! the pattern's slot, its sticking device
      real(dp), intent(in) :: agt             !! the table acceleration now [m/s2]
      real(dp), intent(out) :: fr, fabs       !! the force [N], the magnitude of its terms
      integer :: m
      associate (pat => st%cache%slot(slot))
         fr = pat%fag(r)*agt + st%f0(r)
         fabs = abs(pat%fag(r)*agt) + abs(st%f0(r))
         do m = 1, pat%nq
            fr = fr + pat%fq(r, m)*st%q(m) + pat%fp(r, m)*st%p(m)
            fabs = fabs + abs(pat%fq(r, m)*st%q(m)) + abs(pat%fp(r, m)*st%p(m))
         end do
      end associate
   end subroutine force_now

   !> Magnitudes of the Taylor recursion's terms (|A| |x_k| + ...) to degree m: the
   !> scale against which a level's q_L counts as zero.
   pure subroutine abs_taylor(st, slot, m)
      type(ed_state), intent(inout) :: st     !! the state, the pattern in slot entered
      integer, intent(in) :: slot             !! the pattern's slot
      integer, intent(in) :: m                !! the degree
      integer :: k1, ii, jj
      associate (pat => st%cache%slot(slot))
         do ii = 1, pat%nq
            st%qa(ii, 0) = abs(st%q(ii))
            st%pq(ii, 0) = abs(st%p(ii))
         end do
         do k1 = 0, m - 1
            do ii = 1, pat%nq
               st%qa(ii, k1 + 1) = st%pq(ii, k1)/(k1 + 1)
               st%pq(ii, k1 + 1) = abs(st%g(k1))*abs(pat%lq(ii))
               if (k1 == 0) st%pq(ii, 1) = st%pq(ii, 1) + abs(st%b1(ii))
            end do
            do jj = 1, pat%nq
               do ii = 1, pat%nq
                  st%pq(ii, k1 + 1) = st%pq(ii, k1 + 1) + abs(pat%kt(ii, jj))*st%qa(jj, k1) + &
                                      abs(pat%ct(ii, jj))*st%pq(jj, k1)
               end do
            end do
            do ii = 1, pat%nq
               st%pq(ii, k1 + 1) = st%pq(ii, k1 + 1)/(k1 + 1)
            end do
         end do
      end associate
   end subroutine abs_taylor

   !> b_a' T Mq^-1 T' b_b in a pattern with groups grp and group masses mq.
   pure real(dp) function group_delassus(model, a, b, grp, mq) result(x)
      type(model_type), intent(in) :: model
      integer, intent(in) :: a, b
      integer, intent(in) :: grp(:)
      real(dp), intent(in) :: mq(:)
      integer :: ga(2), gb(2), i, j, ni, nj
      real(dp), parameter :: sg(2) = [1.0_dp, -1.0_dp]
      ga = 0
      gb = 0
      call pair_nodes(model, a, ni, nj)
      ga(1) = grp(ni)
      if (nj > 0) ga(2) = grp(nj)
      call pair_nodes(model, b, ni, nj)
      gb(1) = grp(ni)
      if (nj > 0) gb(2) = grp(nj)
      x = 0.0_dp
      do i = 1, 2
         if (ga(i) == 0) cycle
         do j = 1, 2
            if (gb(j) == ga(i)) x = x + sg(i)*sg(j)/mq(ga(i))
         end do
      end do
   end function group_delassus

   !> Row a of the level-lev LCP in a general pattern: q_L = sgn (T'b_d)' q^(L+2), its
   !> magnitude, and W1(a, b) = sgn_a sgn_b (T'b_a)'(T'b_b) (Mq = I).
   pure subroutine general_level(st, slot, a, lev, ndg)
      type(ed_state), intent(inout) :: st     !! the state, the pattern in slot entered
      integer, intent(in) :: slot, a, lev, ndg !! the pattern, the row, the level, the rows
      integer :: b, g, d

      associate (pat => st%cache%slot(slot))
         d = st%cand(a)
         st%lq(a) = 0.0_dp
         st%lqa(a) = 0.0_dp
         do g = 1, pat%nq
            st%lq(a) = st%lq(a) + pat%tb(g, d)*st%qc(g, lev + 2)
            st%lqa(a) = st%lqa(a) + abs(pat%tb(g, d))*st%qa(g, lev + 2)
         end do
         st%lq(a) = st%sig(a)*st%lq(a)
         do b = 1, ndg
            st%wm(a, b) = st%sig(a)*st%sig(b)*dot_product(pat%tb(1:pat%nq, d), pat%tb(1:pat%nq, st%cand(b)))
         end do
      end associate
   end subroutine general_level

   !> "device d" or "devices d1, d2, ..." of the devices idx(1:m) (at most 20 named).
   subroutine device_list(idx, m, text)
      integer, intent(in) :: idx(:)
      integer, intent(in) :: m
      character(len=:), allocatable, intent(out) :: text
      integer :: a
      text = 'devices '
      if (m == 1) text = 'device '
      do a = 1, min(m, 20)
         text = text//trim(fmt_int(idx(a)))
         if (a < min(m, 20)) text = text//', '
      end do
      if (m > 20) text = text//', ...'
   end subroutine device_list

   subroutine lcp_failed(what, m, idx, info, t, error)
      character(len=*), intent(in) :: what
      integer, intent(in) :: m
      integer, intent(in) :: idx(:)
      type(lcp_info), intent(in) :: info
      real(dp), intent(in) :: t
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: list
      call device_list(idx, m, list)
      call fatal_error(error, "event-driven technique at t = "//trim(fmt_real(t))//" s: "//what// &
                       " of "//list//" was not solved ("//trim(lcp_status_text(info%status))//", residual "// &
                       trim(fmt_real(info%residual))//"); try a small change of the slip loads P mu of "// &
                       "these devices, or technique = 'newmark' with law = 'velocity'")
   end subroutine lcp_failed

end module fd_phase_decision
