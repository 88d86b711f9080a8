!> Response spectra against closed forms: an undamped oscillator under a ramp to a constant
!> acceleration (a motion linear between samples: exact to round-off), a damped one under a
!> sine from rest, and a short pulse against the impulse response.
module test_fd_spectrum
   use testdrive, only: new_unittest, unittest_type, error_type, check, test_failed
   use test_fd_helpers, only: check_close
   use fd_kinds, only: dp
   use fd_error, only: lib_error => error_type
   use fd_spectrum, only: response_spectrum, oscillator_peaks
   implicit none
   private

   public :: collect_spectrum

   real(dp), parameter :: pi = 3.14159265358979323846_dp

contains

   subroutine collect_spectrum(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("ramp to a constant: exact", test_ramp), &
                  new_unittest("sine from rest: closed form", test_sine), &
                  new_unittest("short pulse: impulse response", test_pulse), &
                  new_unittest("period 0 and bad input", test_edges) &
                  ]
   end subroutine collect_spectrum

   !> ag rises linearly from 0 to a0 in the first step and stays: for an undamped oscillator
   !> u = -a0/w^2 (t/tr - sin(w t)/(w tr)) in the ramp, then
   !> u = -a0/w^2 (1 - (sin(w t) - sin(w (t - tr)))/(w tr)). Its peak over the samples (the
   !> oscillator is sampled 20 times a period or more) is the spectrum's value to round-off.
   subroutine test_ramp(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 2001
      real(dp), parameter :: dt = 0.01_dp, a0 = 2.0_dp
      real(dp) :: ag(n), w, t, u, peak, umax, amax, tper(3)
      integer :: i, j, m, k

      ag = a0
      ag(1) = 0.0_dp
      tper = [0.05_dp, 0.7_dp, 3.0_dp]
      do k = 1, 3
         w = 2.0_dp*pi/tper(k)
         m = max(1, ceiling(20.0_dp*dt*w/(2.0_dp*pi)))
         peak = 0.0_dp
         do i = 1, n - 1
            do j = 1, m
               t = (i - 1)*dt + j*dt/m
               if (t <= dt) then
                  u = -a0/w**2*(t/dt - sin(w*t)/(w*dt))
               else
                  u = -a0/w**2*(1.0_dp - (sin(w*t) - sin(w*(t - dt)))/(w*dt))
               end if
               peak = max(peak, abs(u))
            end do
         end do
         call oscillator_peaks(ag, dt, w, 0.0_dp, umax, amax)
         call check_close(error, umax, peak, 1.0e-9_dp, "peak displacement, T = "//trim(adjustl(real_text(tper(k)))))
         if (allocated(error)) return
         ! undamped: the absolute acceleration is -w^2 u
         call check_close(error, amax, w*w*peak, 1.0e-9_dp, "peak absolute acceleration")
         if (allocated(error)) return
      end do
   end subroutine test_ramp

   !> ag = A sin(W t) from rest, 5 % damping: u = e^(-xi w t) (C1 cos wd t + C2 sin wd t)
   !> + G1 sin W t + G2 cos W t. Sampled at T/1000, the sine's linear interpolation differs
   !> from it by (W dt)^2/8 = 3.4e-6 relative at most, which bounds the peak's difference.
   subroutine test_sine(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), parameter :: amp = 3.0_dp, xi = 0.05_dp, tn = 0.5_dp, big_w = 2.0_dp*pi/0.6_dp
      integer, parameter :: n = 60001
      real(dp) :: ag(n), dt, w, wd, d, g1, g2, c1, c2, t, u, peak, umax, amax
      integer :: i

      w = 2.0_dp*pi/tn
      wd = w*sqrt(1.0_dp - xi**2)
      dt = tn/1000.0_dp
      d = (w**2 - big_w**2)**2 + (2.0_dp*xi*w*big_w)**2
      g1 = -amp*(w**2 - big_w**2)/d
      g2 = amp*2.0_dp*xi*w*big_w/d
      c1 = -g2
      c2 = (xi*w*c1 - big_w*g1)/wd
      peak = 0.0_dp
      do i = 1, n
         t = (i - 1)*dt
         ag(i) = amp*sin(big_w*t)
         u = exp(-xi*w*t)*(c1*cos(wd*t) + c2*sin(wd*t)) + g1*sin(big_w*t) + g2*cos(big_w*t)
         peak = max(peak, abs(u))
      end do
      call oscillator_peaks(ag, dt, w, xi, umax, amax)
      call check_close(error, umax, peak, 1.0e-5_dp, "peak displacement under a sine")
      if (allocated(error)) return
      ! near steady state the amplitude is A / sqrt(D): the peak is at least that
      call check(error, umax >= amp/sqrt(d), "the peak reaches the steady amplitude")
   end subroutine test_sine

   !> A triangle of area I over two steps much shorter than the period: the response is the
   !> impulse response u = -(I/wd) e^(-xi w t) sin(wd t) to O((w dt)^2); its peak is
   !> (I/wd) e^(-xi w t1) sin(wd t1) at tan(wd t1) = sqrt(1 - xi^2)/xi.
   subroutine test_pulse(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), parameter :: xi = 0.05_dp, tn = 1.0_dp, dt = 1.0e-4_dp, area = 0.2_dp
      integer, parameter :: n = 20001
      real(dp) :: ag(n), w, wd, t1, exact, umax, amax

      ag = 0.0_dp
      ag(2) = area/dt
      w = 2.0_dp*pi/tn
      wd = w*sqrt(1.0_dp - xi**2)
      t1 = atan(sqrt(1.0_dp - xi**2)/xi)/wd
      exact = area/wd*exp(-xi*w*t1)*sin(wd*t1)
      call oscillator_peaks(ag, dt, w, xi, umax, amax)
      call check_close(error, umax, exact, 1.0e-4_dp, "peak displacement after a pulse")
   end subroutine test_pulse

   subroutine test_edges(error)
      type(error_type), allocatable, intent(out) :: error
      type(lib_error), allocatable :: err
      real(dp) :: sd(2), psv(2), psa(2), sa(2)

      call response_spectrum([0.0_dp, -4.0_dp, 1.0_dp], 0.01_dp, [0.0_dp, 1.0_dp], 0.05_dp, sd, psv, psa, sa, err)
      call check(error, .not. allocated(err), "valid input")
      if (allocated(error)) return
      call check(error, sd(1) == 0.0_dp .and. psa(1) == 4.0_dp .and. sa(1) == 4.0_dp, "T = 0: the PGA")
      if (allocated(error)) return
      call check_close(error, psa(2), (2.0_dp*pi)**2*sd(2), 1.0e-15_dp, "psa = w^2 sd")
      if (allocated(error)) return
      call response_spectrum([0.0_dp, 1.0_dp], 0.01_dp, [1.0_dp, -1.0_dp], 0.05_dp, sd, psv, psa, sa, err)
      call check(error, allocated(err), "a negative period is refused")
      if (allocated(error)) return
      call check(error, index(err%message, "period 2 = -1") > 0, err%message)
      if (allocated(error)) return
      call response_spectrum([0.0_dp, 1.0_dp], 0.01_dp, [1.0_dp, 2.0_dp], 1.0_dp, sd, psv, psa, sa, err)
      call check(error, allocated(err), "xi = 1 is refused")
   end subroutine test_edges

   pure function real_text(x) result(s)
      real(dp), intent(in) :: x
      character(len=16) :: s
      write (s, '(f8.3)') x
   end function real_text

end module test_fd_spectrum
