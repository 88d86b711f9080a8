!> Unit tests of the band alternation count (fd_band_alternation's alternation_step) on force
!> sequences whose second differences are known in closed form: a decaying alternation on a
!> linear course (its amplitude and counted time from the closed form), a jump and a kink
!> (not counted), an alternation broken by slip steps (not counted), and one below the floor.
module test_fd_band_alternation
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_device_state, only: device_state, phase_stick, phase_slip_pos
   use fd_band_alternation, only: alternation_type, band_watch, alternation_step, alternation_floor, alternation_run
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
                  new_unittest("slip steps break the count", test_broken), &
                  new_unittest("below the floor: not counted", test_floor) &
                  ]
   end subroutine collect_band_alternation

   !> One velocity-law device watched (device 1), nothing seen yet.
   subroutine watch_one(al)
      type(alternation_type), intent(out) :: al

      al%n = 1
      al%w = [band_watch(dev=1, floor4=4*alternation_floor*pmu)]
   end subroutine watch_one

   !> Feed forces f(0:) in the phases phase(0:); the amplitude and time counted.
   subroutine feed(f, phase, amp, time)
      real(dp), intent(in) :: f(0:)
      integer, intent(in) :: phase(0:)
      real(dp), intent(out) :: amp, time
      type(alternation_type) :: al
      type(device_state) :: st(1)
      real(dp) :: a(1), t(1)
      integer :: k

      call watch_one(al)
      a = 0.0_dp
      t = 0.0_dp
      do k = 0, ubound(f, 1)
         st(1)%phase = phase(k)
         call alternation_step(al, 1, h, st, f(k:k), a, t)
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

   !> A full alternation +-P mu interrupted by a slip step every fifth step: at most four
   !> forces in the band in a row, never the six a count needs.
   subroutine test_broken(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: f(0:99), amp, time
      integer :: phase(0:99), k

      do k = 0, 99
         f(k) = pmu*(-1)**k
         phase(k) = merge(phase_slip_pos, phase_stick, mod(k, 5) == 4)
      end do
      call feed(f, phase, amp, time)
      call check(error, amp == 0.0_dp .and. time == 0.0_dp, "no six forces in the band in a row")
      if (allocated(error)) return
      phase = phase_stick
      call feed(f, phase, amp, time)
      call check(error, abs(amp - pmu) <= 1e-12_dp*pmu .and. abs(time - (100 - 2)*h) <= 1e-12_dp, &
                 "the same forces all in the band: +-P mu from the third on")
   end subroutine test_broken

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

end module test_fd_band_alternation
