!> Elastic response spectra of a ground motion: the peak response of linear oscillators of
!> period T and damping ratio xi, u'' + 2 xi w u' + w^2 u = -ag(t), from rest. The motion is
!> taken as linear between its samples (as the techniques take it) and each oscillator is
!> integrated exactly for such a motion (the step map of the state with the load's value and
!> slope appended, exp(A h), as Nigam and Jennings, 1969, did in closed form; here by scaling
!> and squaring, without their closed form's cancellation at long periods). The record
!> resolution check runs the structure's modes through a record with the same map. Where a
!> period is short against the record's step,
!> each step is cut into equal parts (the motion still linear in each), so that peaks are
!> sampled at least 20 times a period; the response is exact at every sample, and a peak
!> between samples is missed by at most 1 - cos(pi/20) = 1.2 %. The peaks are over the
!> record's duration (no free vibration after it).
module fd_spectrum
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real
   implicit none
   private

   public :: response_spectrum, oscillator_peaks, exact_step_map

   real(dp), parameter :: pi = 3.14159265358979323846_dp
   !> Samples of the response per period at least.
   integer, parameter :: samples_per_period = 20

contains

   !> Peak relative displacement sd, pseudo-velocity psv = w sd, pseudo-acceleration
   !> psa = w^2 sd and peak absolute acceleration sa of each period's oscillator. A period
   !> of 0 is the rigid oscillator: sd = 0 and psa = sa = the peak ground acceleration.
   subroutine response_spectrum(ag, dt, periods, xi, sd, psv, psa, sa, error)
      real(dp), intent(in) :: ag(:)          !! ground acceleration at the samples [m/s2]
      real(dp), intent(in) :: dt             !! step of the samples [s]
      real(dp), intent(in) :: periods(:)     !! periods [s], >= 0
      real(dp), intent(in) :: xi             !! damping ratio, 0 <= xi < 1
      real(dp), intent(out) :: sd(:)         !! peak relative displacement [m]
      real(dp), intent(out) :: psv(:)        !! pseudo-velocity w sd [m/s]
      real(dp), intent(out) :: psa(:)        !! pseudo-acceleration w^2 sd [m/s2]
      real(dp), intent(out) :: sa(:)         !! peak absolute acceleration [m/s2]
      type(error_type), allocatable, intent(out) :: error !! bad input
      real(dp) :: w
      integer :: p

      if (size(ag) < 2) then
         call fatal_error(error, "response spectrum: the motion has "//trim(fmt_int(size(ag)))// &
                          " samples; it needs at least 2")
         return
      end if
      if (.not. (dt > 0.0_dp .and. dt < huge(dt))) then
         call fatal_error(error, "response spectrum: dt = "//trim(fmt_real(dt))//" s must be finite and > 0")
         return
      end if
      if (.not. (xi >= 0.0_dp .and. xi < 1.0_dp)) then
         call fatal_error(error, "response spectrum: xi = "//trim(fmt_real(xi))//" must be in 0 <= xi < 1")
         return
      end if
      if (size(sd) /= size(periods) .or. size(psv) /= size(periods) .or. size(psa) /= size(periods) .or. &
          size(sa) /= size(periods)) then
         call fatal_error(error, "response spectrum: the outputs differ in size from the periods")
         return
      end if
      do p = 1, size(periods)
         if (.not. (periods(p) >= 0.0_dp .and. periods(p) < huge(dt))) then
            call fatal_error(error, "response spectrum: period "//trim(fmt_int(p))//" = "// &
                             trim(fmt_real(periods(p)))//" s must be finite and >= 0")
            return
         end if
      end do
      do p = 1, size(periods)
         if (periods(p) == 0.0_dp) then
            sd(p) = 0.0_dp
            psv(p) = 0.0_dp
            psa(p) = maxval(abs(ag))
            sa(p) = psa(p)
            cycle
         end if
         w = 2.0_dp*pi/periods(p)
         call oscillator_peaks(ag, dt, w, xi, sd(p), sa(p))
         psv(p) = w*sd(p)
         psa(p) = w*w*sd(p)
      end do
   end subroutine response_spectrum

   !> Peak |u| and peak |u'' + ag| of one oscillator of circular frequency w from rest.
   pure subroutine oscillator_peaks(ag, dt, w, xi, umax, amax)
      real(dp), intent(in) :: ag(:)     !! ground acceleration at the samples [m/s2]
      real(dp), intent(in) :: dt        !! step of the samples [s]
      real(dp), intent(in) :: w         !! circular frequency [rad/s], > 0
      real(dp), intent(in) :: xi        !! damping ratio, 0 <= xi < 1
      real(dp), intent(out) :: umax     !! peak relative displacement [m]
      real(dp), intent(out) :: amax     !! peak absolute acceleration [m/s2]
      real(dp) :: h, phi(2, 2), g0(2), g1(2), u, v, un, p0, p1, acc
      integer :: i, j, m

      ! parts of a step: at least samples_per_period samples a period
      m = max(1, ceiling(samples_per_period*dt*w/(2.0_dp*pi)))
      h = dt/m
      call exact_step_map(w, 2.0_dp*xi*w, h, phi, g0, g1)
      u = 0.0_dp
      v = 0.0_dp
      umax = 0.0_dp
      amax = abs(ag(1))
      do i = 1, size(ag) - 1
         do j = 1, m
            ! p = -ag (unit mass), linear within the step
            p0 = -(ag(i) + (ag(i + 1) - ag(i))*real(j - 1, dp)/m)
            p1 = -(ag(i) + (ag(i + 1) - ag(i))*real(j, dp)/m)
            un = phi(1, 1)*u + phi(1, 2)*v + g0(1)*p0 + g1(1)*p1
            v = phi(2, 1)*u + phi(2, 2)*v + g0(2)*p0 + g1(2)*p1
            u = un
            umax = max(umax, abs(u))
            ! absolute acceleration u'' + ag = -(2 xi w v + w^2 u)
            acc = abs(2.0_dp*xi*w*v + w*w*u)
            amax = max(amax, acc)
         end do
      end do
   end subroutine oscillator_peaks

   !> The exact step of a mode q'' + c q' + wn^2 q = p(t) with p linear in the step:
   !> (q, q')(h) = phi (q, q')(0) + g0 p(0) + g1 p(h). From exp(A h) of the state with the
   !> load's value and slope appended, A = [0 1 0 0; -wn^2 -c 1 0; 0 0 0 1; 0 0 0 0], by
   !> scaling and squaring of its Taylor series (any wn >= 0 and c >= 0: rigid-body,
   !> underdamped and overdamped modes alike).
   pure subroutine exact_step_map(wn, c, h, phi, g0, g1)
      real(dp), intent(in) :: wn        !! natural circular frequency [rad/s]
      real(dp), intent(in) :: c         !! damping per unit modal mass [1/s]
      real(dp), intent(in) :: h         !! step [s]
      real(dp), intent(out) :: phi(2, 2) !! the free response's map
      real(dp), intent(out) :: g0(2), g1(2) !! the response to p(0) and to p(h)
      real(dp) :: a(4, 4), e(4, 4), term(4, 4), nrm
      integer :: s, k

      a = 0.0_dp
      a(1, 2) = h
      a(2, 1) = -wn*wn*h
      a(2, 2) = -c*h
      a(2, 3) = h
      a(3, 4) = 1.0_dp            ! the slope appended as (p(h) - p(0)): its rate 1/h times h
      nrm = maxval(sum(abs(a), dim=1))
      s = 0
      if (nrm > 0.5_dp) s = ceiling(log(nrm/0.5_dp)/log(2.0_dp))
      a = a/2.0_dp**s
      ! Taylor series to 20 terms of a matrix of norm <= 1/2: truncation below 1e-25
      e = 0.0_dp
      do k = 1, 4
         e(k, k) = 1.0_dp
      end do
      term = e
      do k = 1, 20
         term = matmul(term, a)/real(k, dp)
         e = e + term
      end do
      do k = 1, s
         e = matmul(e, e)
      end do
      phi = e(1:2, 1:2)
      ! (q, q')(h) = phi z0 + e(1:2, 3) p(0) + e(1:2, 4) (p(h) - p(0))
      g0 = e(1:2, 3) - e(1:2, 4)
      g1 = e(1:2, 4)
   end subroutine exact_step_map

end module fd_spectrum
