!> Table motion: harmonic table displacement with an optional cosine ramp, or a recorded
!> table acceleration sampled at dt_record and linearly interpolated in between.
module fd_excitation
   use fd_kinds, only: dp
   implicit none
   private

   public :: excitation_type, table_motion
   public :: excitation_none, excitation_harmonic, excitation_record

   integer, parameter :: excitation_none = 0     !! table at rest (free vibration)
   integer, parameter :: excitation_harmonic = 1 !! x0 = a0 R(t) sin(2 pi f t)
   integer, parameter :: excitation_record = 2   !! recorded acceleration samples

   real(dp), parameter :: pi = acos(-1.0_dp)

   !> The table motion of one run.
   type :: excitation_type
      integer :: kind = excitation_none    !! excitation id
      real(dp) :: amplitude = 0.0_dp       !! harmonic displacement amplitude a0 [m]
      real(dp) :: frequency = 0.0_dp       !! harmonic frequency [Hz]
      integer :: ramp_cycles = 0           !! cycles of the cosine ramp (0 = none)
      real(dp) :: duration = 0.0_dp        !! analysed duration [s]
      real(dp) :: dt_record = 0.0_dp       !! record step dt_r [s]
      real(dp), allocatable :: acc(:)      !! recorded table acceleration at k*dt_r [m/s2]
   end type excitation_type

contains

   !> Table displacement, velocity and acceleration at time t. For a record only the
   !> acceleration is defined (xg = vg = 0); after the record's end the table is at rest.
   pure subroutine table_motion(exc, t, xg, vg, ag)
      type(excitation_type), intent(in) :: exc !! the table motion
      real(dp), intent(in) :: t                !! time [s]
      real(dp), intent(out) :: xg              !! table displacement [m]
      real(dp), intent(out) :: vg              !! table velocity [m/s]
      real(dp), intent(out) :: ag              !! table acceleration [m/s2]
      real(dp) :: w, tr, r, r1, r2, s, c, x
      integer :: k, n

      xg = 0.0_dp; vg = 0.0_dp; ag = 0.0_dp
      select case (exc%kind)
      case (excitation_harmonic)
         w = 2.0_dp*pi*exc%frequency
         s = sin(w*t); c = cos(w*t)
         r = 1.0_dp; r1 = 0.0_dp; r2 = 0.0_dp
         if (exc%ramp_cycles > 0) then
            tr = exc%ramp_cycles/exc%frequency
            if (t < tr) then
               ! R = (1 - cos(pi t/tr))/2: R, R' vanish at 0 and R' at tr; x0'' stays
               ! continuous at tr because sin(w tr) = 0 after whole cycles.
               r = 0.5_dp*(1.0_dp - cos(pi*t/tr))
               r1 = 0.5_dp*(pi/tr)*sin(pi*t/tr)
               r2 = 0.5_dp*(pi/tr)**2*cos(pi*t/tr)
            end if
         end if
         xg = exc%amplitude*r*s
         vg = exc%amplitude*(r1*s + r*w*c)
         ag = exc%amplitude*(r2*s + 2.0_dp*r1*w*c - r*w*w*s)
      case (excitation_record)
         n = size(exc%acc)
         if (t < 0.0_dp .or. n == 0) return
         x = t/exc%dt_record
         k = int(x)
         if (k >= n - 1) then
            ! exactly at the last sample, or after the record
            if (k == n - 1 .and. x - k <= 1.0e-9_dp) ag = exc%acc(n)
            return
         end if
         x = x - k
         ag = (1.0_dp - x)*exc%acc(k + 1) + x*exc%acc(k + 2)
      end select
   end subroutine table_motion

end module fd_excitation
