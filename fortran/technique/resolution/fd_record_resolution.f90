!> Whether the main step resolves a recorded table motion: the error the step alone makes in
!> the peak linear response of each mode of the structure to the record, for the stuck and
!> the free system, against the exact response.
!>
!> A record is sampled at dt_record and interpolated linearly, so the table acceleration is
!> linear within every step dt1 = dt_record / n1. A mode q'' + c q' + wn^2 q = -g ag(t) (g its
!> participation) then has an exact discrete solution at the steps (the piecewise-exact
!> method; here the exponential of the mode's matrix with the load's value and slope
!> appended, exact_step_map), and Newmark's (beta, gamma) the recursion the run itself takes.
!> Both are run through the record from the run's initial conditions, mode by mode, in one
!> pass (memory independent of the duration). A mode near a peak of the record's spectrum,
!> lightly damped and integrated with the wrong period, responds with the wrong amplitude: at
!> n1 = 1 (dt1 = dt_record = 0.02 s) a fuzz deck's 9 Hz mode came out with its peak 98 % too
!> large while omega_max dt1 = 1.7 said "resolved". For each DOF the peak is read about the
!> system's equilibrium (the devices stuck at their initial lengths): exactly with one mode;
!> with several, the modes' peak changes are combined by the square root of the sum of their
!> squares (the modal combination of a response-spectrum analysis), against the same
!> combination of the exact peaks plus the equilibrium's offset: record_step_error. Above
!> record_error_limit the summary says "unresolved" and the executable, the command line and
!> the Python API warn. A friction run is not linear, but it moves between these two systems:
!> the verdict (record_system) judges the stuck system when no device slid and every device
!> is hysteretic (the run is then that linear system), the free one when a device slid (the
!> stuck system's error, over the whole record, overstates that of short stick phases), and
!> the larger of the two when none slid but one is a velocity-law device (a dashpot within
!> its band, neither rigid nor absent); both systems' figures are in the summary. Not
!> applicable: a harmonic (fd_harmonic_resolution) or no table motion, no mode of the judged
!> system to estimate (n_modes = 0, or only the modes left out below), or the event-driven
!> technique (no step). The Moreau-Jean technique is judged by its own recursion
!> (theta_step_map), its Coulomb devices as hysteretic ones (no slide: the stuck system).
!> Only the summary's modes are seen (the lowest n_modes): omega_max dt1
!> (fd_mode_resolution) covers the highest. Rigid-body modes are left out (their drift,
!> unbounded without a0, has no step error to speak of and would swamp the others' peaks),
!> and so are summary modes beyond omega dt1 = 2 or Newmark's stability limit
!> (mode_resolution reports them; an estimate of them would be meaningless or diverge). An
!> estimate that is not finite gives the error 1 and "unresolved".
module fd_record_resolution
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use fd_kinds, only: dp
   use fd_error, only: error_type, fmt_int, allocation_error
   use fd_names, only: technique_step_rule, rule_none, rule_newmark, rule_theta, excitation_record
   use fd_stiffness, only: stiffness_times
   use fd_matrices, only: modes_type, modes_kept, mode_damping, mode_participation
   use fd_model, only: model_type
   use fd_friction, only: law_stuck, stuck_dashpot
   use fd_excitation, only: excitation_type, table_acceleration
   use fd_result, only: result_type, run_setup, setup_of, record_error_limit, record_system_none, &
                        record_system_structure, record_system_stuck, record_system_free, record_system_both
   use fd_spectrum, only: exact_step_map
   implicit none
   private

   !> record_error_limit: the relative change of a DOF's combined peak linear response above
   !> which the step does not resolve the record (fd_result's, by which fd_warnings judges)
   public :: record_resolution, exact_step_map, newmark_step_map, theta_step_map, record_error_limit

   !> One pass of the modes of both systems through the record: each mode a row.
   type :: mode_pass
      real(dp), allocatable :: ex(:, :)     !! the exact step maps (8 coefficients a row)
      real(dp), allocatable :: nx(:, :)     !! the run's step maps (12 coefficients a row)
      real(dp), allocatable :: z(:, :)      !! the exact (q, q') and the run's (q, q', q'' or load)
      real(dp), allocatable :: q0(:)        !! q at the start
      real(dp), allocatable :: ext(:, :)    !! largest and smallest q, exact and by the step
      logical, allocatable :: kept(:)       !! the mode is estimated
      real(dp), allocatable :: off(:)       !! per DOF, the system's equilibrium
      real(dp), allocatable :: ku0(:)       !! K u0, the springs' alone
      real(dp) :: h = 0.0_dp                !! dt1 [s]
      real(dp) :: limit = 2.0_dp            !! the largest wn dt1 estimated
      real(dp) :: p0 = 0.0_dp               !! the load at the start (-ag(0))
   end type mode_pass

contains

   !> Newmark's step (beta, gamma, acceleration form as fd_newmark's try_step) of the same mode
   !> as a map: (q, q', q'')(h) = nm (q, q', q'')(0) + np p(h).
   pure subroutine newmark_step_map(wn, c, h, beta, gamma, nm, np)
      real(dp), intent(in) :: wn, c, h, beta, gamma
      real(dp), intent(out) :: nm(3, 3), np(3)
      real(dp) :: keff, b2, g1, ra(3)

      b2 = (0.5_dp - beta)*h*h
      g1 = (1.0_dp - gamma)*h
      keff = 1.0_dp + gamma*h*c + beta*h*h*wn*wn
      ! q~ = q + h q' + b2 q'', v~ = q' + g1 q''; q''(h) = (p(h) - c v~ - wn^2 q~) / keff
      ra = [-wn*wn, -wn*wn*h - c, -wn*wn*b2 - c*g1]/keff
      nm(3, :) = ra
      np(3) = 1.0_dp/keff
      nm(1, :) = [1.0_dp, h, b2] + beta*h*h*ra
      np(1) = beta*h*h*np(3)
      nm(2, :) = [0.0_dp, 1.0_dp, g1] + gamma*h*ra
      np(2) = gamma*h*np(3)
   end subroutine newmark_step_map

   !> The Moreau-Jean technique's theta-method (fd_moreau_jean: v1 - v = h (p_theta - c v_theta
   !> - wn^2 u_theta), u1 = u + h v_theta, the load interpolated as v and u) of the same mode
   !> as a map in the layout of newmark_step_map, its third component the step's starting
   !> load instead of the acceleration: (q, q', p)(h) = nm (q, q', p)(0) + np p(h).
   pure subroutine theta_step_map(wn, c, h, theta, nm, np)
      real(dp), intent(in) :: wn, c, h, theta
      real(dp), intent(out) :: nm(3, 3), np(3)
      real(dp) :: d

      ! v_theta = (v + theta h ((1 - theta) p0 + theta p1) - theta h wn^2 u) / d
      d = 1.0_dp + theta*h*c + (theta*h*wn)**2
      nm(1, :) = [1.0_dp - theta*h*h*wn*wn/d, h/d, theta*(1.0_dp - theta)*h*h/d]
      np(1) = theta*theta*h*h/d
      nm(2, :) = [-h*wn*wn/d, (1.0_dp/d - (1.0_dp - theta))/theta, (1.0_dp - theta)*h/d]
      np(2) = theta*h/d
      nm(3, :) = 0.0_dp
      np(3) = 1.0_dp
   end subroutine theta_step_map

   !> Sets res%record_error_stuck and res%record_error_free (per DOF, for the DOFs whose
   !> combined exact peak is at least 1 % of the largest), res%record_error (that of the
   !> system the run was in) and res%record_checked (the verdict: fd_warnings),
   !> from the summary's modes (res%eng), the record (exc), the technique's dt1, the run's duration and
   !> Newmark's beta, gamma (Moreau-Jean's theta). One pass through the record for the modes
   !> of both systems.
   subroutine record_resolution(model, exc, beta, gamma, theta, res, error)
      type(model_type), intent(in) :: model               !! the model (masses, springs, u0, v0)
      type(excitation_type), intent(in) :: exc            !! the table motion
      real(dp), intent(in) :: beta, gamma                 !! Newmark's parameters
      real(dp), intent(in) :: theta                       !! Moreau-Jean's theta
      type(result_type), intent(inout) :: res             !! the result of the run
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      type(mode_pass) :: ps
      integer :: n, stat, nm, ns, m, judged
      logical :: ok, some
      type(run_setup) :: setup

      n = model%n_dof
      setup = setup_of(res)
      res%record_checked = .false.
      res%record_system = record_system_none
      res%record_error = 0.0_dp               ! allocated with the summary (init_result)
      res%record_error_stuck = 0.0_dp
      res%record_error_free = 0.0_dp
      if (technique_step_rule(res%technique) == rule_none) return
      if (res%eng%excitation /= excitation_record) return
      if (setup%dt1 <= 0.0_dp .or. .not. (exc%duration > 0.0_dp)) return
      judged = judged_system(model, res)
      ns = modes_kept(res%eng%stuck)
      nm = ns
      ! without devices the free system is the stuck one
      if (model%n_devices > 0) nm = ns + modes_kept(res%eng%free)
      if (nm == 0) return
      ! the maps by mode, one row of 8 (exact) and of 12 (Newmark) coefficients per mode: the
      ! pass below runs across the modes, each coefficient contiguous; ext: each mode's
      ! largest and smallest q, exact and by Newmark; kept: the mode is estimated
      allocate (ps%off(n), ps%ku0(n), ps%ex(nm, 8), ps%nx(nm, 12), ps%z(nm, 5), ps%q0(nm), ps%ext(nm, 4), &
                ps%kept(nm), stat=stat)
      call allocation_error(error, stat, "the step check against the record ("//trim(fmt_int(n))//" DOFs)")
      if (allocated(error)) return
      ps%h = setup%dt1
      ! the largest wn dt1 the check integrates: mode_resolution's limit 2, and Newmark's
      ! stability limit 1 / sqrt(gamma / 2 - beta) when it is conditionally stable
      ps%limit = 2.0_dp
      if (technique_step_rule(res%technique) == rule_newmark .and. beta < 0.5_dp*gamma) &
         ps%limit = min(ps%limit, 1.0_dp/sqrt(0.5_dp*gamma - beta))
      call stiffness_times(model, model%u0, ps%ku0)
      ! every mode q'' + c q' + wn^2 q = -g ag (g its participation) from the run's initial
      ! conditions, through the run's dt1 steps (fd_result's count) at the accelerations the
      ! run saw; z: the exact (q, q') and Newmark's (q, q', q'')
      ps%z = 0.0_dp
      ps%p0 = -table_acceleration(exc, 0.0_dp)
      do m = 1, nm
         if (m <= ns) then
            call mode_start(ps, model, res, beta, gamma, theta, res%eng%stuck, m, m)
         else
            call mode_start(ps, model, res, beta, gamma, theta, res%eng%free, m - ns, m)
         end if
      end do
      ! no mode of the judged system to estimate: not applicable (without devices the free
      ! system's modes are the stuck one's)
      select case (judged)
      case (record_system_free)
         some = any(ps%kept(ns + 1:nm))
      case (record_system_both)
         some = any(ps%kept)
      case default
         some = any(ps%kept(1:ns))
      end select
      if (.not. some) return
      call run_pass(ps, exc)
      ok = combine(ps, model%u0(1:n), res%eng%stuck, 0, res%record_error_stuck)
      if (ok .and. nm > ns) ok = combine(ps, model%u0(1:n), res%eng%free, ns, res%record_error_free)
      res%record_system = judged
      res%record_checked = .true.
      if (.not. ok) then
         ! the estimate failed: an error of 1, beyond the limit
         res%record_error = 1.0_dp
         res%record_error_stuck = 1.0_dp
         res%record_error_free = 1.0_dp
         return
      end if
      if (nm == ns) res%record_error_free = res%record_error_stuck
      select case (judged)
      case (record_system_free)
         res%record_error = res%record_error_free
      case (record_system_both)
         res%record_error = max(res%record_error_stuck, res%record_error_free)
      case default
         res%record_error = res%record_error_stuck
      end select
   end subroutine record_resolution

   !> The system the run was in, which the verdict judges: the stuck one when no device slid
   !> and every device is hysteretic (a sticking spring: the run is then that linear
   !> system); the free one when a device slid (from the start or by a transition: the
   !> stuck system's modes, run through the whole record, overstate the error of short
   !> stick phases; on 51 613 fuzz decks, judging it there too added 411 flags, 99 of them
   !> wrong runs); both, the larger, when no device slid and one is a velocity-law device
   !> (within its band a dashpot P mu / eps, neither a rigid link nor absent); the
   !> structure itself without devices.
   pure integer function judged_system(model, res) result(judged)
      type(model_type), intent(in) :: model     !! the model
      type(result_type), intent(in) :: res      !! the run's transitions
      logical :: slid

      ! a device sliding at t = 0 has one slide more than its stick-to-slip transitions
      slid = any(res%slip_excursions > res%stick_to_slip) .or. any(res%stick_to_slip > 0) .or. any(res%slip_to_stick > 0) &
             .or. any(res%reversals > 0)
      if (model%n_devices == 0) then
         judged = record_system_structure
      else if (slid) then
         judged = record_system_free
      else if (all(law_stuck(model%dev(1:model%n_devices)%law) /= stuck_dashpot)) then
         judged = record_system_stuck
      else
         judged = record_system_both
      end if
   end function judged_system

   !> Mode k of the system as row m of the pass: its maps (exact_step_map's phi by rows, g0,
   !> g1; newmark_step_map's nm by rows, np), with the load scaled by its participation,
   !> and its start. The initial conditions' modal coordinates are taken about the system's
   !> equilibrium with its devices stuck where they start (their rest lengths the initial
   !> ones; none for the free system): q(0) = phi' K u0 / (wn^2 phi' M phi), with K the
   !> springs' alone, and q'(0) = phi' M v0 / phi' M phi. Left out (kept false, a zero
   !> row): a rigid-body mode (its drift, unbounded without a0, has no step
   !> error to speak of and would swamp the other modes' peaks), and a mode the step cannot
   !> integrate (beyond omega dt1 = 2, which mode_resolution reports, or unstable).
   pure subroutine mode_start(ps, model, res, beta, gamma, theta, modes, k, m)
      type(mode_pass), intent(inout) :: ps      !! the pass (h, limit, ku0, p0 set)
      type(model_type), intent(in) :: model     !! the model (masses, v0)
      type(result_type), intent(in) :: res      !! the technique, the damping (res%eng%a0)
      real(dp), intent(in) :: beta, gamma       !! Newmark's parameters
      real(dp), intent(in) :: theta             !! Moreau-Jean's theta
      type(modes_type), intent(in) :: modes     !! the system's modes
      integer, intent(in) :: k, m               !! the mode, its row
      real(dp) :: phi(2, 2), g0(2), g1(2), nmap(3, 3), np(3), g, mk, wn, c
      integer :: n

      n = model%n_dof
      ps%ex(m, :) = 0.0_dp
      ps%nx(m, :) = 0.0_dp
      wn = sqrt(max(modes%omega2(k), 0.0_dp))
      c = mode_damping(modes, k, res%eng%a0)
      ps%kept(m) = wn > 0.0_dp .and. wn*ps%h < ps%limit
      if (.not. ps%kept(m)) return
      g = mode_participation(modes, k, model%mass(1:n), model%influence)
      call exact_step_map(wn, c, ps%h, phi, g0, g1)
      ps%ex(m, :) = [phi(1, 1), phi(1, 2), phi(2, 1), phi(2, 2), g*g0(1), g*g0(2), g*g1(1), g*g1(2)]
      if (technique_step_rule(res%technique) == rule_theta) then
         call theta_step_map(wn, c, ps%h, theta, nmap, np)
      else
         call newmark_step_map(wn, c, ps%h, beta, gamma, nmap, np)
      end if
      ps%nx(m, :) = [nmap(1, :), nmap(2, :), nmap(3, :), g*np]
      mk = sum(model%mass(1:n)*modes%shape(:, k)**2)
      ps%z(m, 1) = sum(modes%shape(:, k)*ps%ku0)/(wn*wn*mk)
      ps%z(m, 2) = sum(modes%shape(:, k)*model%mass(1:n)*model%v0(1:n))/mk
      ps%z(m, 3:4) = ps%z(m, 1:2)
      if (technique_step_rule(res%technique) == rule_theta) then
         ps%z(m, 5) = g*ps%p0                                   ! the step's starting load
      else
         ps%z(m, 5) = g*ps%p0 - c*ps%z(m, 2) - wn*wn*ps%z(m, 1)    ! the acceleration
      end if
   end subroutine mode_start

   !> The pass through the record: every mode exactly and by the step's recursion, step by
   !> step at the accelerations the run saw, keeping each mode's largest and smallest q.
   subroutine run_pass(ps, exc)
      type(mode_pass), intent(inout) :: ps      !! the pass, its modes started
      type(excitation_type), intent(in) :: exc  !! the table motion
      real(dp) :: p0, p1, q, v
      integer :: m, step

      ps%q0 = ps%z(:, 1)
      ps%ext(:, 1) = ps%q0
      ps%ext(:, 2) = ps%q0
      ps%ext(:, 3) = ps%q0
      ps%ext(:, 4) = ps%q0
      p0 = ps%p0
      associate (ex => ps%ex, nx => ps%nx, z => ps%z, ext => ps%ext)
         do step = 1, max(1, nint(exc%duration/ps%h))
            p1 = -table_acceleration(exc, step*ps%h)
            !GCC$ ivdep
            do m = 1, size(z, 1)
               q = ex(m, 1)*z(m, 1) + ex(m, 2)*z(m, 2) + ex(m, 5)*p0 + ex(m, 7)*p1
               z(m, 2) = ex(m, 3)*z(m, 1) + ex(m, 4)*z(m, 2) + ex(m, 6)*p0 + ex(m, 8)*p1
               z(m, 1) = q
               ext(m, 1) = max(ext(m, 1), q)
               ext(m, 2) = min(ext(m, 2), q)
               q = nx(m, 1)*z(m, 3) + nx(m, 2)*z(m, 4) + nx(m, 3)*z(m, 5) + nx(m, 10)*p1
               v = nx(m, 4)*z(m, 3) + nx(m, 5)*z(m, 4) + nx(m, 6)*z(m, 5) + nx(m, 11)*p1
               z(m, 5) = nx(m, 7)*z(m, 3) + nx(m, 8)*z(m, 4) + nx(m, 9)*z(m, 5) + nx(m, 12)*p1
               z(m, 4) = v
               z(m, 3) = q
               ext(m, 3) = max(ext(m, 3), q)
               ext(m, 4) = min(ext(m, 4), q)
            end do
            p0 = p1
         end do
      end associate
   end subroutine run_pass

   !> The system's modes (from position first + 1 in the pass) combined DOF by DOF into err.
   !> The run's displacement is u = off + sum_k phi_k q_k, off = u0 - sum_k phi_k q_k(0)
   !> the system's equilibrium (and the part of u0 in the modes left out). With one mode
   !> estimated, a DOF's peak is max |off + phi q| over the mode's largest and smallest q,
   !> exact and by Newmark, and err the change of that peak against it (exact). With several,
   !> the peak is estimated as |off| + the square root of the sum of squares of the modes'
   !> peaks |phi q|, and err is that of the peaks' changes against it. .false. when not
   !> finite.
   logical function combine(ps, u0, modes, first, err) result(finite)
      type(mode_pass), intent(inout) :: ps      !! the pass, run (off is set here)
      real(dp), intent(in) :: u0(:)             !! the initial displacements
      type(modes_type), intent(in) :: modes     !! the system's modes
      integer, intent(in) :: first              !! the row before its first mode
      real(dp), intent(inout) :: err(:)         !! per DOF, the larger kept
      real(dp) :: big, pe, pn, peak(size(u0)), change(size(u0))
      integer :: k, i, m, n

      finite = .true.
      if (modes_kept(modes) == 0) return
      n = size(u0)
      associate (off => ps%off, ext => ps%ext, kept => ps%kept)
         off = u0
         do k = 1, modes%n
            off = off - modes%shape(:, k)*ps%q0(first + k)
         end do
         peak = 0.0_dp
         change = 0.0_dp
         if (count(kept(first + 1:first + modes%n)) == 1) then
            ! the one mode estimated (the others left out stay at q = 0)
            k = findloc(kept(first + 1:first + modes%n), .true., 1)
            m = first + k
            do i = 1, n
               pe = max(abs(off(i) + modes%shape(i, k)*ext(m, 1)), abs(off(i) + modes%shape(i, k)*ext(m, 2)))
               pn = max(abs(off(i) + modes%shape(i, k)*ext(m, 3)), abs(off(i) + modes%shape(i, k)*ext(m, 4)))
               peak(i) = pe
               change(i) = abs(pn - pe)
            end do
         else
            do k = 1, modes%n
               m = first + k
               pe = max(ext(m, 1), -ext(m, 2))
               pn = max(ext(m, 3), -ext(m, 4))
               do i = 1, n
                  peak(i) = peak(i) + (modes%shape(i, k)*pe)**2
                  change(i) = change(i) + (modes%shape(i, k)*(pn - pe))**2
               end do
            end do
            peak = abs(off) + sqrt(peak)
            change = sqrt(change)
         end if
      end associate
      ! tested without an ordered comparison, which a NaN would trap in the checked build:
      ! an estimate that failed is not a "resolved"
      finite = all(ieee_is_finite(peak)) .and. all(ieee_is_finite(change))
      if (.not. finite) return
      big = maxval(peak)
      if (.not. (big > 0.0_dp)) return
      do i = 1, n
         if (peak(i) >= 0.01_dp*big) err(i) = max(err(i), change(i)/peak(i))
      end do
   end function combine

end module fd_record_resolution
