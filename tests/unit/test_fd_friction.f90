!> Unit tests of the paper's two friction laws as state machines (fd_friction_hysteretic,
!> fd_friction_velocity): phase changes at the thresholds of eqs. 2-4 and 6-8, the force
!> coefficients each phase gives (F = ks s + cs sdot + f0), continuity of the force at the
!> changes, and the correctness conditions of eqs. 9 and 12; and the states in which
!> `refinement = 'implicit'` takes a step that ends in a new phase (the return mapping).
!>
!> The values are chosen exact in binary (P mu = 5 N, f = 2**-10 m, eps = eps1 = 2**-7 m/s),
!> so that "at the threshold" is exactly at it.
module test_fd_friction
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_model, only: device_type, law_velocity, law_hysteretic
   use fd_device_state, only: device_state, device_force, phase_stick, phase_slip_pos, phase_slip_neg
   use fd_friction_hysteretic, only: hysteretic_init, hysteretic_update, hysteretic_correct, hysteretic_settle
   use fd_friction, only: friction_settle
   use fd_friction_velocity, only: velocity_init, velocity_update, velocity_correct, velocity_settle
   implicit none
   private

   public :: collect_friction

   real(dp), parameter :: pmu = 5.0_dp            !! P mu [N]
   real(dp), parameter :: f = 2.0_dp**(-10)       !! hysteretic sticking displacement [m]
   real(dp), parameter :: band = 2.0_dp**(-7)     !! eps1 (hysteretic) and eps (velocity) [m/s]
   real(dp), parameter :: n_corr = 10.0_dp        !! n of eqs. 9 and 12

contains

   subroutine collect_friction(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("hysteretic: initial state", test_hys_init), &
                  new_unittest("hysteretic: stick to slip at |F| = P mu", test_hys_yield), &
                  new_unittest("hysteretic: centre follows the slip", test_hys_centre), &
                  new_unittest("hysteretic: unarmed slide", test_hys_unarmed), &
                  new_unittest("hysteretic: eqs. 1, 2 end an armed slide at its turn", test_hys_eq2), &
                  new_unittest("hysteretic: reversal", test_hys_reversal), &
                  new_unittest("hysteretic: no capacity", test_hys_zero), &
                  new_unittest("hysteretic: eq. 12", test_hys_correct), &
                  new_unittest("hysteretic: states of an implicit step", test_hys_settle), &
                  new_unittest("implicit step: states of both laws", test_friction_settle), &
                  new_unittest("velocity: the band, eqs. 6-7", test_vel_band), &
                  new_unittest("velocity: force continuous at the band", test_vel_continuity), &
                  new_unittest("velocity: no capacity", test_vel_zero), &
                  new_unittest("velocity: eq. 9", test_vel_correct) &
                  ]
   end subroutine collect_friction

   pure function device(law) result(dev)
      integer, intent(in) :: law
      type(device_type) :: dev
      dev%node_i = 1
      dev%node_j = 0
      dev%law = law
      dev%p = 10.0_dp
      dev%mu = 0.5_dp
      dev%f = f
      dev%eps = band
      dev%eps1 = band
   end function device

   !> Force of the state st at (s, sdot).
   elemental real(dp) function force(st, s, sdot)
      type(device_state), intent(in) :: st
      real(dp), intent(in) :: s, sdot
      force = device_force(st, s, sdot)
   end function force

   subroutine test_hys_init(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: st
      type(device_type) :: dev

      dev = device(law_hysteretic)
      call check(error, dev%p*dev%mu, pmu, 'P mu of the test device')
      if (allocated(error)) return
      ! at rest: sticking, no force, stiffness P mu / f
      call hysteretic_init(dev, 0.3_dp, 0.5_dp*band, st)
      call check(error, st%phase == phase_stick .and. .not. st%armed, 'starts sticking inside the band')
      if (allocated(error)) return
      call check(error, st%ks, pmu/f, 'sticking stiffness k = P mu / f')
      if (allocated(error)) return
      call check(error, force(st, 0.3_dp, 0.0_dp), 0.0_dp, 'no force at the initial position')
      if (allocated(error)) return
      ! moving at |sdot| >= eps1: sliding (armed), force -P mu
      call hysteretic_init(dev, 0.3_dp, -band, st)
      call check(error, st%phase == phase_slip_neg .and. st%armed, 'starts sliding at |sdot| = eps1')
      if (allocated(error)) return
      call check(error, force(st, 0.3_dp, -band), -pmu, 'sliding force -P mu')
   end subroutine test_hys_init

   !> Sticking at centre 0: F = k s; slides once |F| >= P mu, i.e. at |s| = f (eqs. 3-4),
   !> armed when |sdot| >= eps1 at the onset.
   subroutine test_hys_yield(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: st
      type(device_type) :: dev
      logical :: changed
      real(dp) :: below

      dev = device(law_hysteretic)
      below = f*(1.0_dp - 2.0_dp**(-30))
      call hysteretic_init(dev, 0.0_dp, 0.0_dp, st)
      call hysteretic_update(dev, below, 0.1_dp, st, changed)
      call check(error, st%phase == phase_stick .and. .not. changed, 'sticks while |F| < P mu')
      if (allocated(error)) return
      call check(error, force(st, below, 0.1_dp) < pmu, 'F = k s below P mu')
      if (allocated(error)) return
      call hysteretic_update(dev, f, 0.1_dp, st, changed)
      call check(error, st%phase == phase_slip_pos .and. changed .and. st%armed, &
                 'slides at F = P mu; armed (|sdot| >= eps1)')
      if (allocated(error)) return
      call check(error, force(st, f, 0.1_dp), pmu, 'F = P mu at the onset: continuous')
      if (allocated(error)) return
      ! the other way, slowly: slides negative, not armed
      call hysteretic_init(dev, 0.0_dp, 0.0_dp, st)
      call hysteretic_update(dev, -f, -0.5_dp*band, st, changed)
      call check(error, st%phase == phase_slip_neg .and. changed .and. .not. st%armed, &
                 'slides negative at F = -P mu; not armed (|sdot| < eps1)')
      if (allocated(error)) return
      call check(error, force(st, -f, -0.5_dp*band), -pmu, 'F = -P mu')
   end subroutine test_hys_yield

   !> While sliding the elastic range follows: centre = s - f; when the slide ends (eq. 2)
   !> the force stays P mu and unloading by 2 f reaches -P mu (the loop of Fig. 2).
   subroutine test_hys_centre(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: st
      type(device_type) :: dev
      logical :: changed
      real(dp), parameter :: s_end = 0.25_dp

      dev = device(law_hysteretic)
      call hysteretic_init(dev, 0.0_dp, 2.0_dp*band, st)            ! sliding +, armed
      call hysteretic_update(dev, 0.125_dp, 2.0_dp*band, st, changed)
      call check(error, st%phase == phase_slip_pos .and. .not. changed, 'keeps sliding')
      if (allocated(error)) return
      call check(error, st%centre, 0.125_dp - f, 'centre = s - f while sliding')
      if (allocated(error)) return
      call hysteretic_update(dev, s_end, 0.0_dp, st, changed)   ! eqs. 1, 2: the turn
      call check(error, st%phase == phase_stick .and. changed .and. .not. st%armed, 'the turn ends the slide')
      if (allocated(error)) return
      call check(error, st%centre, s_end - f, 'centre = s - f at the end of the slide')
      if (allocated(error)) return
      call check(error, force(st, s_end, 0.0_dp), pmu, 'F stays P mu when sticking again')
      if (allocated(error)) return
      call hysteretic_update(dev, s_end - f, 0.0_dp, st, changed)
      call check(error, st%phase == phase_stick .and. force(st, s_end - f, 0.0_dp) == 0.0_dp, &
                 'unloaded by f: F = 0, sticking')
      if (allocated(error)) return
      call hysteretic_update(dev, s_end - 2.0_dp*f, -0.1_dp, st, changed)
      call check(error, st%phase == phase_slip_neg .and. changed, 'unloaded by 2 f: slides back')
      if (allocated(error)) return
      call check(error, force(st, s_end - 2.0_dp*f, -0.1_dp), -pmu, 'F = -P mu')
      if (allocated(error)) return
      call check(error, st%centre, s_end - f, 'centre = s + f sliding negative')
   end subroutine test_hys_centre

   !> An unarmed slide (|sdot| has not reached eps1): eq. 2 does not apply; it ends when sdot
   !> turns against the sliding direction, and is armed once |sdot| >= eps1.
   subroutine test_hys_unarmed(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: st, st0
      type(device_type) :: dev
      logical :: changed

      dev = device(law_hysteretic)
      call hysteretic_init(dev, 0.0_dp, 0.0_dp, st)
      call hysteretic_update(dev, f, 0.25_dp*band, st, changed)
      call check(error, st%phase == phase_slip_pos .and. .not. st%armed, 'unarmed slide')
      if (allocated(error)) return
      st0 = st
      call hysteretic_update(dev, 2.0_dp*f, 0.5_dp*band, st, changed)
      call check(error, st%phase == phase_slip_pos .and. .not. changed .and. .not. st%armed, &
                 '|sdot| < eps1 does not end an unarmed slide')
      if (allocated(error)) return
      call hysteretic_update(dev, 3.0_dp*f, band, st, changed)
      call check(error, st%phase == phase_slip_pos .and. .not. changed .and. st%armed, 'armed at |sdot| = eps1')
      if (allocated(error)) return
      st = st0
      call hysteretic_update(dev, 1.5_dp*f, 0.0_dp, st, changed)
      call check(error, st%phase == phase_stick .and. changed, 'sdot = 0 ends an unarmed slide')
      if (allocated(error)) return
      call check(error, force(st, 1.5_dp*f, 0.0_dp), pmu, 'F continuous at the end of the slide')
      if (allocated(error)) return
      st = st0
      call hysteretic_update(dev, 1.5_dp*f, -0.25_dp*band, st, changed)
      call check(error, st%phase == phase_stick .and. changed, 'sdot against the slide ends it')
   end subroutine test_hys_unarmed

   !> An armed slide ends by eq. 2 when |sdot| < eps1 and sdot has turned (sdot sgn <= 0: the
   !> extremum of s, eq. 1), and not at |sdot| = eps1. In the band still along the slide it
   !> slides on, unarmed, to its turn: ended there, the residual velocity would carry the
   !> elastic force past P mu within a step (a one-step stick, two transitions for one stop).
   subroutine test_hys_eq2(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: st, st0
      type(device_type) :: dev
      logical :: changed
      real(dp), parameter :: s1 = -2.0_dp**(-6)

      dev = device(law_hysteretic)
      call hysteretic_init(dev, 0.0_dp, -3.0_dp*band, st)
      st0 = st
      call hysteretic_update(dev, s1, -band, st, changed)
      call check(error, st%phase == phase_slip_neg .and. .not. changed .and. st%armed, &
                 '|sdot| = eps1: still sliding, armed')
      if (allocated(error)) return
      st = st0
      call hysteretic_update(dev, s1, -band*(1.0_dp - 2.0_dp**(-40)), st, changed)
      call check(error, st%phase == phase_slip_neg .and. .not. changed .and. .not. st%armed, &
                 '|sdot| just below eps1, along the slide: slides on, unarmed')
      if (allocated(error)) return
      call check(error, force(st, s1, -0.5_dp*band), -pmu, 'F = -P mu sliding on')
      if (allocated(error)) return
      call hysteretic_update(dev, s1 - f/8, 2.0_dp**(-30), st, changed)
      call check(error, st%phase == phase_stick .and. changed, 'sticks at the turn')
      if (allocated(error)) return
      call check(error, force(st, s1 - f/8, 0.0_dp), -pmu, 'F continuous at -P mu')
      if (allocated(error)) return
      st = st0
      call hysteretic_update(dev, s1, 0.5_dp*band, st, changed)
      call check(error, st%phase == phase_stick .and. changed .and. .not. st%armed, &
                 'turned within the band in one step: sticks (eq. 2)')
      if (allocated(error)) return
      call check(error, force(st, s1, 0.0_dp), -pmu, 'F continuous at -P mu')
      if (allocated(error)) return
      st = st0
      call hysteretic_update(dev, s1, 0.0_dp, st, changed)
      call check(error, st%phase == phase_stick .and. changed, 'sdot = 0: sticks (eq. 1)')
   end subroutine test_hys_eq2

   !> An armed slide whose velocity crossed the band in one step reverses.
   subroutine test_hys_reversal(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: st
      type(device_type) :: dev
      logical :: changed

      dev = device(law_hysteretic)
      call hysteretic_init(dev, 0.0_dp, 2.0_dp*band, st)
      call hysteretic_update(dev, 0.02_dp, -2.0_dp*band, st, changed)
      call check(error, st%phase == phase_slip_neg .and. changed .and. st%armed, 'reverses, still armed')
      if (allocated(error)) return
      call check(error, force(st, 0.02_dp, -2.0_dp*band), -pmu, 'F = -P mu after the reversal')
      if (allocated(error)) return
      call check(error, st%centre, 0.02_dp + f, 'centre = s + f')
   end subroutine test_hys_reversal

   !> `refinement = 'implicit'`: a slide that starts is taken in its sliding force P mu sgn
   !> throughout (never above P mu), unarmed (eq. 12 is for steps inside a slide); a slide
   !> that ends is the step in the slide, and the sticking state after it (the update's)
   !> keeps the force continuous; a reversal through the band cannot be taken in one phase.
   !> (A device that keeps its phase keeps its state: friction_settle, below.)
   subroutine test_hys_settle(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: st0, st1, st
      type(device_type) :: dev
      logical :: changed, can

      dev = device(law_hysteretic)
      ! a slide that starts: the trial's stick ended beyond f, at 2 f, with |sdot| >= eps1
      call hysteretic_init(dev, 0.0_dp, 0.0_dp, st0)
      st1 = st0
      call hysteretic_update(dev, 2.0_dp*f, 3.0_dp*band, st1, changed)
      call check(error, changed .and. st1%armed, 'the trial ends in an armed slide')
      if (allocated(error)) return
      call hysteretic_settle(dev, 3.0_dp*band, st0, st1, st, can)
      call check(error, can .and. st%phase == phase_slip_pos .and. .not. st%armed, &
                 'the step is taken sliding +, unarmed')
      if (allocated(error)) return
      call check(error, force(st, 0.3_dp, -7.0_dp), pmu, 'F = P mu whatever s and sdot: no overshoot')
      if (allocated(error)) return
      call check(error, hysteretic_correct(dev, n_corr, st, 0.0_dp, 3.0_dp*band), &
                 'eq. 12 not applied to the first step of a slide')
      if (allocated(error)) return
      ! a slide that ends (eqs. 1, 2: turned within the band): the step in the slide, then
      ! sticking at F = P mu
      call hysteretic_init(dev, 0.0_dp, 3.0_dp*band, st0)
      st1 = st0
      call hysteretic_update(dev, 2.0_dp**(-6), -0.5_dp*band, st1, changed)
      call check(error, changed .and. st1%phase == phase_stick, 'the trial ends sticking')
      if (allocated(error)) return
      call hysteretic_settle(dev, -0.5_dp*band, st0, st1, st, can)
      call check(error, can .and. st%phase == phase_slip_pos .and. st%f0 == st0%f0 .and. st%armed, &
                 'the step is the slide itself')
      if (allocated(error)) return
      call check(error, force(st1, 2.0_dp**(-6), 0.0_dp), force(st, 2.0_dp**(-6), -0.5_dp*band), &
                 'F continuous at the step end')
      if (allocated(error)) return
      ! a reversal through the band
      st1 = st0
      call hysteretic_update(dev, 0.02_dp, -2.0_dp*band, st1, changed)
      call check(error, st1%phase == phase_slip_neg, 'the trial reverses')
      if (allocated(error)) return
      call hysteretic_settle(dev, -2.0_dp*band, st0, st1, st, can)
      call check(error, .not. can, 'a reversal is not taken in one phase')
      if (allocated(error)) return
      ! an unarmed slide ends at any turn of its velocity: within the band it is settled, beyond
      ! it (the velocity crossed the band) it is not
      call hysteretic_init(dev, 0.0_dp, 0.0_dp, st0)
      call hysteretic_update(dev, f, 0.5_dp*band, st0, changed)
      call check(error, st0%phase == phase_slip_pos .and. .not. st0%armed, 'an unarmed slide')
      if (allocated(error)) return
      st1 = st0
      call hysteretic_update(dev, f, -0.5_dp*band, st1, changed)
      call check(error, st1%phase == phase_stick, 'turns: sticks')
      if (allocated(error)) return
      call hysteretic_settle(dev, -0.5_dp*band, st0, st1, st, can)
      call check(error, can .and. st%phase == phase_slip_pos, 'turned within the band: the step in the slide')
      if (allocated(error)) return
      st1 = st0
      call hysteretic_update(dev, f, -2.0_dp*band, st1, changed)
      call hysteretic_settle(dev, -2.0_dp*band, st0, st1, st, can)
      call check(error, st1%phase == phase_stick .and. .not. can, 'turned beyond the band: not settled')
   end subroutine test_hys_settle

   !> friction_settle over both laws: a device that keeps its phase keeps its state, a
   !> velocity-law device takes the coefficients of the phase it ends in, a hysteretic one
   !> the return mapping's; can is false as soon as one device cannot be settled.
   subroutine test_friction_settle(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_type) :: dev(3)
      type(device_state) :: st0(3), st1(3), st(3)
      logical :: changed, can

      dev(1) = device(law_velocity)
      dev(2) = device(law_hysteretic)
      dev(3) = device(law_hysteretic)
      call velocity_init(dev(1), 0.0_dp, 0.0_dp, st0(1))      ! in the band
      call hysteretic_init(dev(2), 0.0_dp, 0.0_dp, st0(2))    ! sticking
      call hysteretic_init(dev(3), 0.0_dp, 3.0_dp*band, st0(3)) ! sliding +
      st1 = st0
      call velocity_update(dev(1), 0.0_dp, 2.0_dp*band, st1(1), changed)    ! leaves the band
      call hysteretic_update(dev(2), 0.5_dp*f, 0.0_dp, st1(2), changed)      ! keeps sticking
      call friction_settle(3, dev, [2.0_dp*band, 0.0_dp, 3.0_dp*band], st0, st1, st, can)
      call check(error, can, 'every change can be settled')
      if (allocated(error)) return
      call check(error, st(1)%phase == phase_slip_pos .and. st(1)%f0 == pmu .and. st(1)%cs == 0.0_dp, &
                 'velocity law: the sliding force of the phase it ends in')
      if (allocated(error)) return
      call check(error, st(2)%phase == phase_stick .and. st(2)%centre == st0(2)%centre, &
                 'unchanged: the start state')
      if (allocated(error)) return
      call hysteretic_update(dev(3), 0.02_dp, -2.0_dp*band, st1(3), changed) ! reversal
      call friction_settle(3, dev, [2.0_dp*band, 0.0_dp, -2.0_dp*band], st0, st1, st, can)
      call check(error, .not. can, 'one reversal: the step cannot be settled')
      if (allocated(error)) return
      ! the velocity law's reversal, slip + to slip -, passed through the band
      call velocity_init(dev(1), 0.0_dp, 2.0_dp*band, st0(1))
      st1(1) = st0(1)
      call velocity_update(dev(1), 0.0_dp, -2.0_dp*band, st1(1), changed)
      call check(error, st0(1)%phase == phase_slip_pos .and. st1(1)%phase == phase_slip_neg, &
                 'velocity law: the trial reverses')
      if (allocated(error)) return
      call velocity_settle(st0(1), st1(1), st(1), can)
      call check(error, .not. can, 'velocity law: a reversal is not taken in one phase')
      if (allocated(error)) return
      st1(1) = st0(1)
      call velocity_update(dev(1), 0.0_dp, 0.5_dp*band, st1(1), changed)
      call velocity_settle(st0(1), st1(1), st(1), can)
      call check(error, can .and. st(1)%phase == phase_stick .and. st(1)%cs == pmu/band, &
                 'velocity law: into the band, its coupling P mu / eps')
   end subroutine test_friction_settle

   subroutine test_hys_zero(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: st
      type(device_type) :: dev
      logical :: changed

      dev = device(law_hysteretic)
      dev%p = 0.0_dp
      call hysteretic_init(dev, 0.0_dp, 1.0_dp, st)
      call check(error, st%phase == phase_stick, 'P mu = 0: never slides, even moving')
      if (allocated(error)) return
      call hysteretic_update(dev, 1.0_dp, 1.0_dp, st, changed)
      call check(error, st%phase == phase_stick .and. .not. changed .and. force(st, 1.0_dp, 1.0_dp) == 0.0_dp, &
                 'P mu = 0: F = 0 anywhere')
   end subroutine test_hys_zero

   !> Eq. 12 in an armed slide: sdot(t) sdot(t - dt) > eps1^2 (1 - 1/n); not checked while
   !> sticking or in an unarmed slide.
   subroutine test_hys_correct(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: st
      type(device_type) :: dev
      real(dp) :: limit

      dev = device(law_hysteretic)
      limit = band**2*(1.0_dp - 1.0_dp/n_corr)
      call hysteretic_init(dev, 0.0_dp, band, st)   ! armed slide
      call check(error, hysteretic_correct(dev, n_corr, st, band, band), 'sdot^2 = eps1^2 > limit')
      if (allocated(error)) return
      call check(error, hysteretic_correct(dev, n_corr, st, band, 0.95_dp*band), '0.95 eps1^2 > limit')
      if (allocated(error)) return
      call check(error, .not. hysteretic_correct(dev, n_corr, st, band, limit/band), 'product = limit: violated')
      if (allocated(error)) return
      call check(error, .not. hysteretic_correct(dev, n_corr, st, band, -band), 'a sign change: violated')
      if (allocated(error)) return
      st%armed = .false.
      call check(error, hysteretic_correct(dev, n_corr, st, band, -band), 'unarmed slide: not checked')
      if (allocated(error)) return
      call hysteretic_init(dev, 0.0_dp, 0.0_dp, st)
      call check(error, hysteretic_correct(dev, n_corr, st, band, -band), 'sticking: not checked')
   end subroutine test_hys_correct

   !> Eqs. 6-7: inside |sdot| < eps a viscous force c1 sdot, c1 = P mu / eps; outside
   !> P mu sgn(sdot); the phase follows the velocity at the end of the step (eq. 8).
   subroutine test_vel_band(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: st
      type(device_type) :: dev
      logical :: changed

      dev = device(law_velocity)
      call velocity_init(dev, 0.0_dp, 0.5_dp*band, st)
      call check(error, st%phase == phase_stick, 'inside the band: sticking phase')
      if (allocated(error)) return
      call check(error, st%cs == pmu/band .and. st%ks == 0.0_dp .and. st%f0 == 0.0_dp, 'F = (P mu / eps) sdot')
      if (allocated(error)) return
      call velocity_update(dev, 0.1_dp, band, st, changed)
      call check(error, st%phase == phase_slip_pos .and. changed, '|sdot| = eps: sliding (eq. 7)')
      if (allocated(error)) return
      call check(error, force(st, 0.1_dp, 7.0_dp), pmu, 'F = P mu whatever the speed')
      if (allocated(error)) return
      call velocity_update(dev, 0.1_dp, 3.0_dp*band, st, changed)
      call check(error, st%phase == phase_slip_pos .and. .not. changed, 'still sliding: no change')
      if (allocated(error)) return
      call velocity_update(dev, 0.1_dp, -band, st, changed)
      call check(error, st%phase == phase_slip_neg .and. changed, 'sliding negative')
      if (allocated(error)) return
      call check(error, force(st, 0.1_dp, -band), -pmu, 'F = -P mu')
      if (allocated(error)) return
      call velocity_update(dev, 0.1_dp, -band*(1.0_dp - 2.0_dp**(-40)), st, changed)
      call check(error, st%phase == phase_stick .and. changed, 'back inside the band')
   end subroutine test_vel_band

   !> The force is continuous across the band edge: c1 eps = P mu.
   subroutine test_vel_continuity(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: inside, outside
      type(device_type) :: dev
      real(dp) :: v_in

      dev = device(law_velocity)
      v_in = band*(1.0_dp - 2.0_dp**(-40))
      call velocity_init(dev, 0.0_dp, v_in, inside)
      call velocity_init(dev, 0.0_dp, band, outside)
      call check(error, abs(force(inside, 0.0_dp, v_in) - force(outside, 0.0_dp, band)) <= 1.0e-11_dp*pmu, &
                 'F jumps by less than 1e-11 P mu across |sdot| = eps')
   end subroutine test_vel_continuity

   subroutine test_vel_zero(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: st
      type(device_type) :: dev

      dev = device(law_velocity)
      dev%mu = 0.0_dp
      call velocity_init(dev, 0.0_dp, 1.0_dp, st)
      call check(error, st%phase == phase_stick .and. force(st, 0.0_dp, 1.0_dp) == 0.0_dp, &
                 'P mu = 0: F = 0 and no sliding phase')
   end subroutine test_vel_zero

   !> Eq. 9 while sliding: sdot(t) sdot(t - dt) > eps^2 (1 - 1/n); not checked in the band.
   subroutine test_vel_correct(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: st
      type(device_type) :: dev
      real(dp) :: limit

      dev = device(law_velocity)
      limit = band**2*(1.0_dp - 1.0_dp/n_corr)
      call velocity_init(dev, 0.0_dp, -band, st)
      call check(error, velocity_correct(dev, n_corr, st, -band, -band), 'eps^2 > limit')
      if (allocated(error)) return
      call check(error, .not. velocity_correct(dev, n_corr, st, -band, -0.9_dp*band*(1.0_dp - 2.0_dp**(-40))), &
                 'just below the limit: violated')
      if (allocated(error)) return
      call check(error, .not. velocity_correct(dev, n_corr, st, -band, 0.1_dp), 'sign change: violated')
      if (allocated(error)) return
      call velocity_init(dev, 0.0_dp, 0.0_dp, st)
      call check(error, velocity_correct(dev, n_corr, st, -band, 0.1_dp), 'in the band: not checked')
   end subroutine test_vel_correct

end module test_fd_friction
