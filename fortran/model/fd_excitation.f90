!> Table motion: harmonic table displacement with an optional cosine ramp, or a recorded
!> table acceleration sampled at dt_record and linearly interpolated in between. Every
!> technique takes the table motion from here: its value at a time (table_motion) or at the
!> points of a time step's grid (grid_motion, without a sine per step), and,
!> for a technique that integrates the forcing exactly, its form on a segment of time:
!> a sum of sines (harmonic motion, the ramp included), linear between samples (a record),
!> or zero (forcing_form, table_sines, ramp_end).
module fd_excitation
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error
   use fd_names, only: excitation_none, excitation_harmonic, excitation_record
   use fd_model, only: model_type
   implicit none
   private

   public :: excitation_type, table_motion, table_acceleration, ramp_end
   public :: grid_motion, grid_init, grid_acceleration
   public :: excitation_none, excitation_harmonic, excitation_record
   public :: sine_forcing, max_sines, table_sines, segment_end, table_taylor, forcing_frequency
   public :: forcing_form, forcing_unknown, forcing_zero, forcing_sines, forcing_linear
   public :: second_table_motion

   real(dp), parameter :: pi = acos(-1.0_dp)

   integer, parameter :: max_sines = 3        !! sines of the table acceleration on a segment

   integer, parameter :: forcing_unknown = -1 !! no exact form known for this excitation
   integer, parameter :: forcing_zero = 0     !! the table is at rest
   integer, parameter :: forcing_sines = 1    !! a sum of sines on each segment (table_sines)
   integer, parameter :: forcing_linear = 2   !! linear between the samples at k dt_record

   !> Table acceleration on one segment of time as a sum of sines, sum_k amp(k) sin(w(k) t).
   type :: sine_forcing
      integer :: nf = 0                        !! number of sines (0: none)
      real(dp) :: w(max_sines) = 0.0_dp        !! circular frequencies [rad/s]
      real(dp) :: amp(max_sines) = 0.0_dp      !! amplitudes [m/s2]
   end type sine_forcing

   integer, parameter :: grid_shift = 6       !! log2 of grid_block: a point's block by a shift
   integer, parameter :: grid_block = 2**grid_shift !! grid points per block of grid_motion

   !> The table acceleration at the points t = k h of a grid (the ends of a run's dt1 steps)
   !> of harmonic motion without a ramp, without a sine per point: with k = b + j, b a multiple
   !> of grid_block, sin(w k h) = sin(w b h) cos(w j h) + cos(w b h) sin(w j h), the sine and
   !> cosine of w j h tabulated once and those of w b h taken once per block. Each term is
   !> rounded once, so the value is within a few ulp of the amplitude of a0 w^2 sin(w k h)
   !> (nothing accumulates from block to block); other table motions take table_acceleration.
   !> State of one run (it lives in the run's workspace).
   type :: grid_motion
      logical :: tabulated = .false.              !! harmonic without a ramp: the tables hold
      real(dp) :: h = 0.0_dp                      !! grid step [s]
      real(dp) :: w = 0.0_dp                      !! circular frequency [rad/s]
      real(dp) :: amp = 0.0_dp                    !! -a0 w^2 [m/s2]
      integer :: block = -1                       !! block whose sine and cosine are in sb, cb
      real(dp) :: sb = 0.0_dp, cb = 0.0_dp        !! sin and cos of w b h
      real(dp) :: sj(0:grid_block - 1) = 0.0_dp   !! sin(w j h)
      real(dp) :: cj(0:grid_block - 1) = 0.0_dp   !! cos(w j h)
   end type grid_motion

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
            tr = ramp_end(exc)
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

   !> Table acceleration at time t: the ag of table_motion, to the last bit, without the
   !> displacement and velocity a time step does not need (harmonic motion after its ramp:
   !> one sine, not a sine and a cosine).
   pure real(dp) function table_acceleration(exc, t) result(ag)
      type(excitation_type), intent(in) :: exc !! the table motion
      real(dp), intent(in) :: t                !! time [s]
      real(dp) :: w, xg, vg

      if (exc%kind == excitation_harmonic .and. exc%ramp_cycles == 0) then
         w = 2.0_dp*pi*exc%frequency
         ag = -(exc%amplitude*(w*w*sin(w*t)))
      else
         call table_motion(exc, t, xg, vg, ag)
      end if
   end function table_acceleration

   !> Set up the grid t = k h of the table acceleration (grid_motion).
   pure subroutine grid_init(exc, h, grid)
      type(excitation_type), intent(in) :: exc !! the table motion
      real(dp), intent(in) :: h                !! grid step [s]
      type(grid_motion), intent(out) :: grid   !! the grid
      integer :: j

      grid%h = h
      grid%tabulated = exc%kind == excitation_harmonic .and. exc%ramp_cycles == 0
      if (.not. grid%tabulated) return
      grid%w = 2.0_dp*pi*exc%frequency
      grid%amp = -(exc%amplitude*(grid%w*grid%w))
      do j = 0, grid_block - 1
         grid%sj(j) = sin(grid%w*(j*h))
         grid%cj(j) = cos(grid%w*(j*h))
      end do
   end subroutine grid_init

   !> Table acceleration at t = k h of the grid: from the tables for the harmonic motion they
   !> hold (table_acceleration's value to round-off), else table_acceleration at t, the same
   !> time as the caller computes it (a record's value to the bit).
   pure subroutine grid_acceleration(exc, grid, k, t, ag)
      type(excitation_type), intent(in) :: exc   !! the table motion
      type(grid_motion), intent(inout) :: grid   !! the grid (grid_init)
      integer, intent(in) :: k                   !! grid point, >= 0
      real(dp), intent(in) :: t                  !! its time, k h up to round-off [s]
      real(dp), intent(out) :: ag                !! table acceleration at k h [m/s2]
      real(dp) :: x
      integer :: b, j

      if (.not. grid%tabulated) then
         ag = table_acceleration(exc, t)
         return
      end if
      b = shiftr(k, grid_shift)                  ! k / grid_block and its remainder, k >= 0
      j = iand(k, grid_block - 1)
      if (b /= grid%block) then
         x = grid%w*(real(b, dp)*grid_block*grid%h)
         grid%sb = sin(x)
         grid%cb = cos(x)
         grid%block = b
      end if
      ag = grid%amp*(grid%sb*grid%cj(j) + grid%cb*grid%sj(j))
   end subroutine grid_acceleration

   !> A time-step loop's second horizontal component exc2 (absent, or of kind none: none): on
   !> when it moves the table, then the technique's copy of it (exc) and its load mr2 = M r2 of
   !> a unit of it (r2 the model's influence2). An error when the model gives no direction of
   !> it, or one the technique cannot take (takes: .false.).
   subroutine second_table_motion(model, takes, on, exc, mr2, error, exc2)
      type(model_type), intent(in) :: model         !! the model
      logical, intent(in) :: takes                  !! the technique takes the model's r2
      logical, intent(out) :: on                    !! a second component moves the table
      type(excitation_type), intent(inout) :: exc   !! then exc2
      real(dp), allocatable, intent(inout) :: mr2(:) !! then M r2
      type(error_type), allocatable, intent(out) :: error !! no direction of it
      type(excitation_type), intent(in), optional :: exc2 !! the second component

      on = .false.
      if (.not. present(exc2)) return
      if (exc2%kind == excitation_none) return
      if (.not. (allocated(model%influence2) .and. takes)) then
         call fatal_error(error, "a second horizontal component needs the model's direction of it "// &
                          "(a building of rigid floors, &floors, or influence2 of &matrices)")
         return
      end if
      on = .true.
      exc = exc2
      mr2 = model%mass*model%influence2
   end subroutine second_table_motion

   !> End of the cosine ramp of harmonic table motion, t_r = ramp_cycles / frequency [s].
   pure real(dp) function ramp_end(exc)
      type(excitation_type), intent(in) :: exc !! the table motion (harmonic, ramp_cycles > 0)

      ramp_end = exc%ramp_cycles/exc%frequency
   end function ramp_end

   !> The form of the table acceleration, for a technique that integrates it exactly.
   pure integer function forcing_form(exc) result(form)
      type(excitation_type), intent(in) :: exc !! the table motion

      select case (exc%kind)
      case (excitation_none)
         form = forcing_zero
      case (excitation_harmonic)
         form = forcing_sines
      case (excitation_record)
         form = forcing_linear
      case default
         form = forcing_unknown
      end select
   end function forcing_form

   !> The table acceleration of harmonic motion on the segment containing t as a sum of
   !> sines: a0 w^2 sin(w t) after the ramp; during it a0 R sin(w t) with
   !> R = (1 - cos(nu t))/2, nu = pi / t_r, twice differentiated, is exactly three sines.
   !> A segment ends at t_r (to 1e-12 relative). nf = 0 for other excitations.
   pure subroutine table_sines(exc, t, frc)
      type(excitation_type), intent(in) :: exc !! the table motion
      real(dp), intent(in) :: t                !! a time in the segment [s]
      type(sine_forcing), intent(out) :: frc   !! the sines of that segment
      real(dp) :: om, nu

      frc%nf = 0
      if (exc%kind /= excitation_harmonic) return
      om = 2.0_dp*pi*exc%frequency
      if (exc%ramp_cycles > 0 .and. t < ramp_end(exc)*(1.0_dp - 1.0e-12_dp)) then
         nu = pi/ramp_end(exc)
         frc%nf = 3
         frc%w = [om + nu, om - nu, om]
         frc%amp = exc%amplitude*[(om + nu)**2/4.0_dp, (om - nu)**2/4.0_dp, -om**2/2.0_dp]
      else
         frc%nf = 1
         frc%w(1) = om
         frc%amp(1) = -exc%amplitude*om**2
      end if
   end subroutine table_sines

   !> Where a step from t towards tn must stop so as not to straddle a change of the form
   !> of the forcing: the end of the harmonic ramp, or the next sample of a record (the
   !> acceleration is linear between samples only); that time if it lies in (t, tn) (to
   !> 1e-12 of tn), else tn. A time within 1e-9 dt_record of a sample counts as that sample.
   pure real(dp) function segment_end(exc, t, tn) result(tb)
      type(excitation_type), intent(in) :: exc !! the table motion
      real(dp), intent(in) :: t                !! start of the step [s]
      real(dp), intent(in) :: tn               !! intended end of the step [s]
      integer :: k

      tb = tn
      select case (exc%kind)
      case (excitation_harmonic)
         if (exc%ramp_cycles > 0) then
            if (t < ramp_end(exc) .and. ramp_end(exc) < tn - 1.0e-12_dp*tn) tb = ramp_end(exc)
         end if
      case (excitation_record)
         k = record_segment(exc, t)
         if (k < size(exc%acc) - 1) then
            if ((k + 1)*exc%dt_record < tn - 1.0e-12_dp*tn) tb = (k + 1)*exc%dt_record
         end if
      end select
   end function segment_end

   !> The sample interval [k dt_r, (k + 1) dt_r) of a record that starts at or contains t
   !> (a time within 1e-9 dt_r below a sample counts as that sample); size(acc) - 1 or
   !> more: after the record.
   pure integer function record_segment(exc, t) result(k)
      type(excitation_type), intent(in) :: exc !! a record
      real(dp), intent(in) :: t                !! time [s]

      k = max(0, floor(t/exc%dt_record + 1.0e-9_dp))
   end function record_segment

   !> Taylor coefficients of the table acceleration about t on the segment that starts at
   !> t (segment_end): ag(t + s) = sum_{j <= k} g(j) s^j + r_k(s), with
   !> |r_k(s)| <= gn(k) s^(k+1) for every degree k <= ubound(g) (gn(k) >= sup |ag^(k+1)| /
   !> (k+1)! over the segment). Harmonic motion: the series of its sines; a record: its
   !> linear piece (gn(k) = 0 for k >= 1); none, or after a record: 0.
   pure subroutine table_taylor(exc, t, g, gn)
      type(excitation_type), intent(in) :: exc !! the table motion
      real(dp), intent(in) :: t                !! expansion point [s]
      real(dp), intent(out) :: g(0:)           !! Taylor coefficients (degree >= 1)
      real(dp), intent(out) :: gn(0:)          !! remainder factors, same bounds
      type(sine_forcing) :: frc
      real(dp) :: sw, cw, f, x, slope
      integer :: kf, k, kk, n

      g = 0.0_dp
      gn = 0.0_dp
      kk = ubound(g, 1)
      select case (exc%kind)
      case (excitation_harmonic)
         call table_sines(exc, t, frc)
         do kf = 1, frc%nf
            sw = sin(frc%w(kf)*t)
            cw = cos(frc%w(kf)*t)
            f = frc%amp(kf)
            do k = 0, kk
               if (k > 0) f = f*frc%w(kf)/k
               select case (mod(k, 4))
               case (0)
                  g(k) = g(k) + f*sw
               case (1)
                  g(k) = g(k) + f*cw
               case (2)
                  g(k) = g(k) - f*sw
               case default
                  g(k) = g(k) - f*cw
               end select
               gn(k) = gn(k) + abs(f)*frc%w(kf)/(k + 1)
            end do
         end do
      case (excitation_record)
         n = size(exc%acc)
         k = record_segment(exc, t)
         if (k >= n - 1) return
         x = t/exc%dt_record - k
         slope = exc%acc(k + 2) - exc%acc(k + 1)
         g(0) = exc%acc(k + 1) + x*slope
         g(1) = slope/exc%dt_record
         gn(0) = abs(g(1))
      end select
   end subroutine table_taylor

   !> The highest circular frequency of the table acceleration's sines (harmonic motion,
   !> its ramp included) [rad/s]; 0 for a record or a table at rest.
   pure real(dp) function forcing_frequency(exc) result(w)
      type(excitation_type), intent(in) :: exc !! the table motion

      w = 0.0_dp
      if (exc%kind /= excitation_harmonic) return
      w = 2.0_dp*pi*exc%frequency
      if (exc%ramp_cycles > 0) w = w + pi/ramp_end(exc)
   end function forcing_frequency

end module fd_excitation
