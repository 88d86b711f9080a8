!> Unit tests of the band alternation count (fd_band_alternation's alternation_step) on force
!> sequences whose second differences are known in closed form: a decaying alternation on a
!> linear course (its amplitude and counted time from the closed form), a jump and a kink
!> (not counted), band and slide in turn at the band's edge (counted), an alternation of
!> sliding forces or one broken by slides (not counted), and one below the floor; a bearing
!> whose observed normal force falls below the deck's (alternation_normal_force) counts an
!> alternation above 5 % of the smaller N mu; band_x in closed form at the start, and again at
!> the end only where a range grew (alternation_init, alternation_finish).
module test_fd_band_alternation
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_device_state, only: device_state, phase_stick, phase_slip_pos, phase_slip_neg
   use fd_band_alternation, only: alternation_type, band_watch, alternation_step, alternation_floor, alternation_run, &
                                  alternation_normal_force, alternation_init, alternation_finish
   use fd_error, only: fd_error_type => error_type
   use test_fd_helpers, only: pairs_of
   use fd_model, only: model_type, device_type
   use fd_result, only: result_type
   implicit none
   private

   public :: collect_band_alternation

   real(dp), parameter :: pmu = 1000.0_dp   !! P mu of the device watched [N]
   real(dp), parameter :: h = 1.0e-3_dp     !! step [s]

contains

   subroutine collect_band_alternation(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("a decaying alternation: its amplitude and time in closed form", test_decaying), &
                  new_unittest("a jump and a kink are not alternations", test_kinks), &
                  new_unittest("band and slide in turn: the band's edge", test_edge), &
                  new_unittest("slides alone, or slides between, break the count", test_broken), &
                  new_unittest("steps of two lengths: a line is not counted, +-A is", test_uneven), &
                  new_unittest("below the floor: not counted", test_floor), &
                  new_unittest("a bearing's observed N: the floor at the smallest", test_observed_floor), &
                  new_unittest("band_x at the start, at the end where a range grew", test_band_x) &
                  ]
   end subroutine collect_band_alternation

   !> One velocity-law device watched (device 1), nothing seen yet.
   subroutine watch_one(al)
      type(alternation_type), intent(out) :: al

      al%n = 1
      al%w = [band_watch(dev=1, floor4=4*alternation_floor*pmu)]
   end subroutine watch_one

   !> Feed forces f(0:) in the phases phase(0:), after steps of length h (or steps(0:));
   !> the amplitude and time counted.
   subroutine feed(f, phase, amp, time, steps)
      real(dp), intent(in) :: f(0:)
      integer, intent(in) :: phase(0:)
      real(dp), intent(out) :: amp, time
      real(dp), intent(in), optional :: steps(0:)
      type(alternation_type) :: al
      type(device_state) :: st(1)
      real(dp) :: a(1), t(1), hk
      integer :: k

      call watch_one(al)
      a = 0.0_dp
      t = 0.0_dp
      do k = 0, ubound(f, 1)
         st(1)%phase = phase(k)
         hk = h
         if (present(steps)) hk = steps(k)
         call alternation_step(al, 1, hk, st, f(k:k), a, t)
      end do
      amp = a(1)
      time = t(1)
   end subroutine feed

   !> F_k = 100 + 3 k + A0 r^k, r = -0.9: the linear course has D = 0 and the alternation
   !> D_k = A0 r^(k-2) (1 - r)^2, |D_k| = A0 |r|^(k-2) (1 + |r|)^2. The first D (k = 2) starts
   !> the run, k = 2 + alternation_run makes it an alternation, and it is counted from k = 2
   !> on as long as |D| exceeds 4 alternation_floor P mu: its largest |D| / 4 is the first's.
   subroutine test_decaying(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: kmax = 400
      real(dp) :: f(0:kmax), amp, time, a0, r, dk
      integer :: phase(0:kmax), k, counted

      a0 = 0.8_dp*pmu
      r = -0.9_dp
      phase = phase_stick
      do k = 0, kmax
         f(k) = 100.0_dp + 3.0_dp*k + a0*r**k
      end do
      call feed(f, phase, amp, time)
      counted = 0
      do k = 2, kmax
         dk = a0*abs(r)**(k - 2)*(1 + abs(r))**2
         if (dk <= 4*alternation_floor*pmu) exit
         counted = counted + 1
      end do
      call check(error, counted > alternation_run + 10, "the closed form counts steps")
      if (allocated(error)) return
      call check(error, abs(amp - a0*(1 + abs(r))**2/4) <= 1e-10_dp*amp, "amplitude |D| / 4 of the run's first D")
      if (allocated(error)) return
      call check(error, abs(time - counted*h) <= 1e-12_dp, "time: the run's steps")
   end subroutine test_decaying

   !> A jump of P mu (D = J, then -J, then 0: one sign change) and a kink of slope P mu a step
   !> (one D): neither reaches alternation_run sign changes.
   subroutine test_kinks(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: f(0:40), amp, time
      integer :: phase(0:40), k

      phase = phase_stick
      f = 0.0_dp
      f(20:) = pmu
      call feed(f, phase, amp, time)
      call check(error, amp == 0.0_dp .and. time == 0.0_dp, "a jump is not counted")
      if (allocated(error)) return
      do k = 0, 40
         f(k) = pmu*max(0, k - 20)
      end do
      call feed(f, phase, amp, time)
      call check(error, amp == 0.0_dp .and. time == 0.0_dp, "a kink is not counted")
   end subroutine test_kinks

   !> The band's edge: band forces -P mu (1 - b q^j) short of the slide's (k = 2 j) in turn
   !> with sliding forces -P mu (k odd). In closed form D_2j = P mu b q^(j-1) (1 + q) and
   !> D_2j+1 = -2 P mu b q^j: alternating, decaying, the first the largest; counted from k = 2
   !> on while |D| exceeds 4 alternation_floor P mu.
   subroutine test_edge(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: kmax = 60
      real(dp), parameter :: b = 0.25_dp, q = 0.9_dp
      real(dp) :: f(0:kmax), amp, time, dk
      integer :: phase(0:kmax), k, counted

      do k = 0, kmax
         if (mod(k, 2) == 0) then
            phase(k) = phase_stick
            f(k) = -pmu*(1 - b*q**(k/2))
         else
            phase(k) = phase_slip_neg
            f(k) = -pmu
         end if
      end do
      call feed(f, phase, amp, time)
      counted = 0
      do k = 2, kmax
         if (mod(k, 2) == 0) then
            dk = pmu*b*q**(k/2 - 1)*(1 + q)
         else
            dk = 2*pmu*b*q**(k/2)
         end if
         if (dk <= 4*alternation_floor*pmu) exit
         counted = counted + 1
      end do
      call check(error, counted > alternation_run + 5, "the closed form counts steps")
      if (allocated(error)) return
      call check(error, abs(amp - pmu*b*(1 + q)/4) <= 1e-12_dp*pmu, "amplitude |D| / 4 of the run's first D")
      if (allocated(error)) return
      call check(error, abs(time - counted*h) <= 1e-12_dp, "time: the run's steps")
   end subroutine test_edge

   !> A full alternation +-P mu in slides alone (the correctness condition's to report), then
   !> with one band force every fifth step: at most three D's in a row reach the band, never
   !> the four a count needs.
   subroutine test_broken(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: f(0:99), amp, time
      integer :: phase(0:99), k

      do k = 0, 99
         f(k) = pmu*(-1)**k
      end do
      phase = phase_slip_pos
      call feed(f, phase, amp, time)
      call check(error, amp == 0.0_dp .and. time == 0.0_dp, "a slide's forces are not counted")
      if (allocated(error)) return
      do k = 0, 99
         phase(k) = merge(phase_stick, phase_slip_pos, mod(k, 5) == 4)
      end do
      call feed(f, phase, amp, time)
      call check(error, amp == 0.0_dp .and. time == 0.0_dp, "three D's in a row reach the band")
      if (allocated(error)) return
      phase = phase_stick
      call feed(f, phase, amp, time)
      call check(error, abs(amp - pmu) <= 1e-12_dp*pmu .and. abs(time - (100 - 2)*h) <= 1e-12_dp, &
                 "the same forces all in the band: +-P mu from the third on")
   end subroutine test_broken

   !> Steps of two lengths in turn, h and h / 7 (as dt1 and dt2 steps where transitions are
   !> refined): a force on a steep line, F = P mu (-1 + 0.8 t / h) (a force crossing the band),
   !> whose unweighted F_k - 2 F_(k-1) + F_(k-2) = +-0.8 P mu 6 / 7 would alternate, is not
   !> counted; the same line plus +-A (A = 0.3 P mu) is, with |D| / 4 = A for every D.
   subroutine test_uneven(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: kmax = 40
      real(dp) :: f(0:kmax), steps(0:kmax), tk, amp, time, d2, d3
      integer :: phase(0:kmax), k

      phase = phase_stick
      tk = 0.0_dp
      do k = 0, kmax
         steps(k) = merge(h/7, h, mod(k, 2) == 1)
         tk = tk + steps(k)
         f(k) = pmu*(-1 + 0.8_dp*tk/h)
      end do
      d2 = f(2) - 2*f(1) + f(0)
      d3 = f(3) - 2*f(2) + f(1)
      call check(error, d2*d3 < 0 .and. min(abs(d2), abs(d3)) > 4*alternation_floor*pmu, &
                 "the steps would make the unweighted difference alternate")
      if (allocated(error)) return
      call feed(f, phase, amp, time, steps)
      call check(error, amp == 0.0_dp .and. time == 0.0_dp, "a line over uneven steps")
      if (allocated(error)) return
      do k = 0, kmax
         f(k) = f(k) + 0.3_dp*pmu*(-1)**k
      end do
      call feed(f, phase, amp, time, steps)
      call check(error, abs(amp - 0.3_dp*pmu) <= 1e-12_dp*pmu, "+-A over uneven steps: A")
      if (allocated(error)) return
      call check(error, abs(time - (sum(steps) - steps(0) - steps(1))) <= 1e-12_dp, &
                 "counted from the first D on")
   end subroutine test_uneven

   !> A steady alternation of 0.9 of the floor: |D| = 3.6 floor P mu, below 4 floor P mu.
   subroutine test_floor(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: f(0:99), amp, time
      integer :: phase(0:99), k

      phase = phase_stick
      do k = 0, 99
         f(k) = 0.9_dp*alternation_floor*pmu*(-1)**k
      end do
      call feed(f, phase, amp, time)
      call check(error, amp == 0.0_dp .and. time == 0.0_dp, "below the floor")
   end subroutine test_floor

   !> A velocity-law bearing component (P mu = pmu, constant mu) watched at the deck's P; the
   !> observer sees its N fall to 0.6 P and rise to 1.3 P: the floor moves to 0.6 P mu
   !> (4 alternation_floor 0.6 pmu), and a steady alternation of 0.8 of the deck's floor, not
   !> counted at P, is counted at 0.6 P (|D| = 3.2 floor pmu > 4 floor 0.6 pmu). A range that
   !> does not grow leaves the watch as it is.
   subroutine test_observed_floor(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(result_type) :: res
      type(alternation_type) :: al
      type(device_state) :: st(1)
      real(dp) :: a(1), t(1), p, f
      integer :: k

      p = 1.0e4_dp
      model%n_devices = 1
      model%dev = [device_type(p=p, mu=pmu/p, eps=1.0e-3_dp, partner=2, component=1)]
      res%n_bearings = 1
      res%bearing_n_min = [p]
      res%bearing_n_max = [p]
      al%n = 1
      al%w = [band_watch(dev=1, floor4=4*alternation_floor*pmu, bearing=1, nlo=p, nhi=p)]
      call alternation_normal_force(model, al, res)
      call check(error, al%w(1)%floor4 == 4*alternation_floor*pmu .and. .not. al%moved, "the deck's range kept")
      if (allocated(error)) return
      res%bearing_n_min = [0.6_dp*p]
      res%bearing_n_max = [1.3_dp*p]
      call alternation_normal_force(model, al, res)
      call check(error, abs(al%w(1)%floor4 - 4*alternation_floor*0.6_dp*pmu) <= 1e-12_dp*pmu, &
                 "the floor at the smallest N")
      if (allocated(error)) return
      call check(error, al%moved .and. al%w(1)%nlo == 0.6_dp*p .and. al%w(1)%nhi == 1.3_dp*p, "the range joined")
      if (allocated(error)) return
      st(1)%phase = phase_stick
      a = 0.0_dp
      t = 0.0_dp
      do k = 0, 19
         f = 0.8_dp*alternation_floor*pmu*(-1)**k
         call alternation_step(al, 1, h, st, [f], a, t)
      end do
      call check(error, abs(a(1) - 0.8_dp*alternation_floor*pmu) <= 1e-12_dp*pmu, "counted at the smaller N")
   end subroutine test_observed_floor

   !> One velocity-law device (P mu = 1000 N, eps = 1e-3 m/s) from a 10 kg mass to the table,
   !> average acceleration at dt1 = 1e-3 s: band_x = (1 - gamma) dt1 P mu / (eps m) = 50 from
   !> alternation_init; alternation_finish takes it again only where the N range grew (at its
   !> largest N: 100 for twice the deck's p), and leaves it otherwise.
   subroutine test_band_x(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(result_type) :: res
      type(alternation_type) :: al
      type(fd_error_type), allocatable :: err
      real(dp), parameter :: p = 1.0e4_dp, dt1 = 1.0e-3_dp, gamma = 0.5_dp

      model%n_dof = 1
      model%mass = [10.0_dp]
      model%n_devices = 1
      model%dev = [device_type(node_i=1, node_j=0, p=p, mu=pmu/p, eps=1.0e-3_dp)]
      call pairs_of(model)
      allocate (res%band_x(1))
      res%band_x = 0.0_dp
      call alternation_init(model, dt1, gamma, al, res, err)
      call check(error, .not. allocated(err), "an error")
      if (allocated(error)) return
      call check(error, al%n == 1 .and. res%band_checked .and. .not. al%moved, "the device watched")
      if (allocated(error)) return
      call check(error, abs(res%band_x(1) - 50.0_dp) <= 1e-13_dp*50, "band_x at the deck's p")
      if (allocated(error)) return
      res%band_x = 0.0_dp
      call alternation_finish(model, dt1, gamma, al, res, err)
      call check(error, .not. allocated(err) .and. res%band_x(1) == 0.0_dp, "band_x taken again, no range grew")
      if (allocated(error)) return
      al%w(1)%nhi = 2*p
      al%moved = .true.
      call alternation_finish(model, dt1, gamma, al, res, err)
      call check(error, .not. allocated(err) .and. abs(res%band_x(1) - 100.0_dp) <= 1e-13_dp*100, &
                 "band_x at the largest N of a range that grew")
      if (allocated(error)) return
      call check(error, .not. al%moved, "the range's move taken")
   end subroutine test_band_x

end module test_fd_band_alternation
