!> Whether the step damps the velocity-law devices' bands (Newmark technique), or leaves
!> their forces alternating from step to step.
!>
!> A velocity-law device inside its band |s'| < eps is a dashpot c1 = P mu(eps) / eps between
!> its two masses (eq. 6): a first-order mode of rate c1 / m_r (m_r = m_i m_j / (m_i + m_j),
!> m_i for a device to the table), far faster than the structure when eps is small. Newmark's
!> rule gives it the amplification r = (1 - 2 (1 - gamma) x) / (1 + 2 gamma x) a step, with
!> x = c1 h / (2 m_r): for average acceleration (1 - x) / (1 + x), negative once x > 1. A
!> relative velocity that the band has not yet brought to its holding value (a device enters
!> the band near |s'| = eps with the force P mu, where holding the masses together takes far
!> less; a neighbour's transition changes that holding force) then alternates in sign from
!> step to step and decays like |r|^k, where the model's decays like exp(-2 x k). The band's
!> force c1 s' carries the alternation, +-A about its smooth course: the device's force
!> history, and the absolute accelerations of its masses (+-A / m), but not the displacements
!> (the trapezoid averages it out). Nothing else reports it while it costs no digits
!> (fd_result's 'digits lost' catches the extreme), and the static x > 1 cannot tell a run
!> that has it from one that does not (the paper's tests 1-3 have x = 1.3-1.9 and none).
!>
!> At the band's edge the same factor leaves the device in the band and out of it in turn: a
!> band step sends |s'| just above eps, the slide's P mu brings it back (a sliding force
!> alternating with a band force c1 s' short of it, both of one sign).
!>
!> Measured on the force of each velocity-law device at its accepted steps (alternation_step,
!> called by the technique after each accepted step; no allocation in the loop): the second
!> difference D_k = 2 (h_(k-1) (F_k - F_(k-1)) - h_k (F_(k-1) - F_(k-2))) / (h_k + h_(k-1))
!> (F_k - 2 F_(k-1) + F_(k-2) for steps of one length) over three forces in a row of which at
!> least one is in the band: a run may start with the slide before the band (the device enters
!> it with the force P mu, the alternation's first term), and three sliding forces in a row end
!> it (a slide's force alternating is the correctness condition's to report). Weighted by the
!> steps' lengths h, D is 0 on a linear course whatever the steps (a force crossing the band in
!> dt2 and dt1 steps is not an alternation). An alternation of amplitude A gives |D| = 4 A with
!> the sign of D changing at every step; a smooth force |D| ~ h^2 |F''|; a jump of the force
!> one sign change (D = J, -J, 0), a one-step spike two, and a kink one large D. A run of D's
!> above 4 alternation_floor P mu, each of the sign opposite to the last, is an alternation
!> once it has changed sign alternation_run times (six forces, which a jump, a spike or a kink
!> cannot give); it is counted from its first D on: the largest |D| / 4 of the counted runs is
!> the device's band_alternation (N), their steps' time its band_alternation_time (s). A
!> device with a count is 'unresolved' (band_resolution). Every run also reports each device's
!> band_x = 2 (1 - gamma) x at dt1, above 1 where the factor r is negative, with the couplings
!> of every velocity-law device at its nodes (exact for one device or devices in parallel on
!> two masses alone).
!>
!> A planar bearing whose normal force N varies over the run: its band dashpot is N mu(eps) / eps,
!> so band_x is taken at N_max (the largest dashpot, the factor r most negative: where the step
!> alternates most), and the floor of the count at N_min (the smallest capacity: an alternation
!> of 5 % of the smallest N mu is counted); a bearing that lifts off (N_min <= 0) has its floor
!> at N_max. [N_min, N_max] is the range predicted before the run (a vertical component's, nrange
!> of alternation_init) joined with the bearing's N observed at the accepted states (fd_result's
!> bearing_n_min and bearing_n_max, which the overturning's dN moves beyond the prediction): the
!> technique calls alternation_normal_force after each accepted state's N is observed (the floor
!> follows a range that grew, so a step is counted against the smallest N seen up to it), and
!> alternation_finish at the end of the run (band_x at the run's largest N).
module fd_band_alternation
   use fd_kinds, only: dp
   use fd_error, only: error_type, fmt_int, allocation_error
   use fd_model, only: model_type, device_type, sliding_mu
   use fd_kinematics, only: add_device_abs, device_abs_inverse_mass_relative
   use fd_friction, only: holds_when_stuck, law_checks_band_alternation
   use fd_device_state, only: device_state, phase_stick
   use fd_result, only: result_type, device_bearings
   implicit none
   private

   public :: alternation_type, band_watch, alternation_init, alternation_step, alternation_normal_force
   public :: alternation_finish
   public :: alternation_floor, alternation_run

   !> Share of P mu below which an alternation is not counted.
   real(dp), parameter :: alternation_floor = 0.05_dp
   !> Sign changes of D in a row, each above the floor, before an alternation is counted:
   !> six forces, which a jump, a spike or a kink cannot give.
   integer, parameter :: alternation_run = 3

   !> A device watched and what the step needs of its last forces.
   type :: band_watch
      integer :: dev = 0                      !! its number
      integer :: nin = 0                      !! of f1, f2, those seen (0, 1 or 2)
      logical :: band1 = .false., band2 = .false. !! f1, f2 in the band
      integer :: run = -1                     !! sign changes in the current run of D's above
                                              !! the floor (-1: no run)
      real(dp) :: floor4 = 0.0_dp             !! 4 alternation_floor P mu: the |D| counted [N]
      real(dp) :: f1 = 0.0_dp, f2 = 0.0_dp    !! forces at the last two accepted steps [N]
      real(dp) :: d1 = 0.0_dp                 !! the last D, times its steps' mean length [N s]
      real(dp) :: h1 = 0.0_dp                 !! the step that ended at f1 [s]
      real(dp) :: dmax = 0.0_dp               !! the run's largest |D| [N]
      real(dp) :: trun = 0.0_dp               !! the run's time not yet counted [s]
      integer :: bearing = 0                  !! its planar bearing (0: none)
      real(dp) :: nlo = 0.0_dp, nhi = 0.0_dp  !! the N range its floor and band_x are at [N]
   end type band_watch

   !> The velocity-law devices watched (one array of records: the step loads one descriptor).
   type :: alternation_type
      integer :: n = 0                        !! devices watched: velocity law, P mu(eps) > 0
      type(band_watch), allocatable :: w(:)   !! each of them
      logical :: moved = .false.              !! a range grew beyond the one band_x was taken at
                                              !! (or band_x not yet taken)
   end type alternation_type

contains

   !> The devices watched, every device's x at dt1 (res%band_x), and band_checked
   !> 'resolved' when there is one ('not applicable' otherwise). x of a device between nodes
   !> i and j: (1 - gamma) dt1 (c_i / m_i + c_j / m_j), c_n the band couplings P mu(eps) / eps
   !> of every velocity-law device at node n (the table, n = 0, adds nothing), so that the
   !> step's factor on the band is negative where x > 1: c1 dt1 / (2 m_r) for one device and
   !> average acceleration.
   subroutine alternation_init(model, dt1, gamma, al, res, error, nrange)
      type(model_type), intent(in) :: model         !! the model
      real(dp), intent(in) :: dt1                   !! main step [s]
      real(dp), intent(in) :: gamma                 !! Newmark's gamma
      type(alternation_type), intent(out) :: al     !! the devices watched
      type(result_type), intent(inout) :: res       !! band_x and band_checked set
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      real(dp), intent(in), optional :: nrange(:, :) !! (2, n_devices) each device's smallest and
                                                     !! largest normal force over the run [N]
                                                     !! (absent: the deck's p throughout)
      integer, allocatable :: bof(:)
      integer :: d, q, stat
      real(dp) :: pmu, pfloor

      res%band_checked = .false.
      al%n = count(watched(model%dev(1:model%n_devices)))
      allocate (al%w(al%n), bof(model%n_devices), stat=stat)
      call allocation_error(error, stat, "the bands of "//trim(fmt_int(al%n))//" velocity-law devices")
      if (stat /= 0) return
      call device_bearings(res, bof)
      q = 0
      do d = 1, model%n_devices
         associate (dev => model%dev(d))
            if (.not. watched(dev)) cycle
            q = q + 1
            al%w(q) = band_watch(dev=d, bearing=bof(d), nlo=dev%p, nhi=dev%p)
            if (present(nrange)) then
               al%w(q)%nlo = nrange(1, d)
               al%w(q)%nhi = nrange(2, d)
            end if
            call band_capacity(dev, al%w(q), pmu, pfloor)
            al%w(q)%floor4 = 4.0_dp*alternation_floor*pfloor
         end associate
      end do
      al%moved = .true.
      call alternation_finish(model, dt1, gamma, al, res, error)
      res%band_checked = al%n > 0
   end subroutine alternation_init

   !> Every watched device's x at dt1 (res%band_x), each velocity-law device's band coupling
   !> at the largest N of its range, where the ranges moved since it was last taken (al%moved:
   !> from alternation_init, and at the end of the run where a bearing's N range grew during it);
   !> nothing otherwise.
   subroutine alternation_finish(model, dt1, gamma, al, res, error)
      type(model_type), intent(in) :: model         !! the model
      real(dp), intent(in) :: dt1                   !! main step [s]
      real(dp), intent(in) :: gamma                 !! Newmark's gamma
      type(alternation_type), intent(inout) :: al   !! the devices watched; moved cleared
      type(result_type), intent(inout) :: res       !! band_x
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      real(dp), allocatable :: c(:)
      integer :: d, q, stat
      real(dp) :: pmu, pfloor, scale

      if (.not. al%moved) return
      allocate (c(model%n_dof), stat=stat)
      call allocation_error(error, stat, "the bands of "//trim(fmt_int(al%n))//" velocity-law devices")
      if (stat /= 0) return
      c = 0.0_dp
      do q = 1, al%n
         d = al%w(q)%dev
         call band_capacity(model%dev(d), al%w(q), pmu, pfloor)
         call add_device_abs(model, d, pmu/model%dev(d)%eps, c)
      end do
      scale = max(0.0_dp, 1.0_dp - gamma)*dt1
      do q = 1, al%n
         res%band_x(al%w(q)%dev) = device_abs_inverse_mass_relative(model, al%w(q)%dev, c, scale)
      end do
      al%moved = .false.
   end subroutine alternation_finish

   !> P mu(eps) of a watched device's band dashpot and of its count's floor at its N range
   !> (the deck's p when the range is one value).
   pure subroutine band_capacity(dev, b, pmu, pfloor)
      type(device_type), intent(in) :: dev          !! the device as the deck made it
      type(band_watch), intent(in) :: b             !! its watch, its N range
      real(dp), intent(out) :: pmu                  !! P mu(eps) of the dashpot [N]
      real(dp), intent(out) :: pfloor               !! P mu(eps) of the floor [N]

      pmu = dev%p*sliding_mu(dev, dev%eps)
      pfloor = pmu
      call varying_band(dev, b%nlo, b%nhi, pmu, pfloor)
   end subroutine band_capacity

   !> The watched bearings' N ranges joined with the N observed so far (res%bearing_n_min,
   !> res%bearing_n_max, the observer's at the accepted states): a range that grew moves the
   !> count's floor to it. Called after each accepted state's normal forces are observed; no
   !> allocation.
   pure subroutine alternation_normal_force(model, al, res)
      type(model_type), intent(in) :: model         !! the model
      type(alternation_type), intent(inout) :: al   !! the devices watched
      type(result_type), intent(in) :: res          !! the bearings' observed N
      real(dp) :: lo, hi, pmu, pfloor
      integer :: q, b

      do q = 1, al%n
         b = al%w(q)%bearing
         if (b == 0) cycle
         lo = min(al%w(q)%nlo, res%bearing_n_min(b))
         hi = max(al%w(q)%nhi, res%bearing_n_max(b))
         if (.not. (lo < al%w(q)%nlo .or. hi > al%w(q)%nhi)) cycle
         al%w(q)%nlo = lo
         al%w(q)%nhi = hi
         call band_capacity(model%dev(al%w(q)%dev), al%w(q), pmu, pfloor)
         al%w(q)%floor4 = 4.0_dp*alternation_floor*pfloor
         al%moved = .true.
      end do
   end subroutine alternation_normal_force

   !> A device whose normal force varies over the run (nlo < nhi): P mu(eps) of its band's
   !> dashpot at the largest N, of the count's floor at the smallest (at the largest when it
   !> lifts off, N_min <= 0); both kept otherwise.
   pure subroutine varying_band(dev, nlo, nhi, pmu, pfloor)
      type(device_type), intent(in) :: dev          !! the device as the deck made it
      real(dp), intent(in) :: nlo, nhi              !! its smallest and largest N [N]
      real(dp), intent(inout) :: pmu                !! P mu(eps) of the dashpot [N]
      real(dp), intent(inout) :: pfloor             !! P mu(eps) of the floor [N]
      real(dp) :: mu

      if (.not. nlo < nhi) return
      mu = sliding_mu(dev, dev%eps)
      pmu = max(nhi, 0.0_dp)*mu
      pfloor = max(nlo, 0.0_dp)*mu
      if (.not. pfloor > 0.0_dp) pfloor = pmu
   end subroutine varying_band

   !> A device the step may leave alternating: the velocity law with a band coupling,
   !> P mu(eps) > 0 (one that holds its nodes while it sticks).
   elemental logical function watched(dev)
      type(device_type), intent(in) :: dev

      watched = law_checks_band_alternation(dev%law) .and. holds_when_stuck(dev)
   end function watched

   !> An accepted step of length h: the watched devices' forces at its end (f, in the phases
   !> st of the next step) join their second differences; a counted alternation raises amp
   !> (res%band_alternation) and adds h to time (res%band_alternation_time).
   !> (Explicit-shape arrays: the call passes addresses only, no descriptors; it is made at
   !> every accepted step.)
   pure subroutine alternation_step(al, nd, h, st, f, amp, time)
      type(alternation_type), intent(inout) :: al   !! the devices watched, their last forces
      integer, intent(in) :: nd                     !! devices
      real(dp), intent(in) :: h                     !! the step's length [s]
      type(device_state), intent(in) :: st(nd)     !! every device's state at the step's end
      real(dp), intent(in) :: f(nd)                 !! every device's force at the step's end [N]
      real(dp), intent(inout) :: amp(nd)            !! per device: largest alternation counted [N]
      real(dp), intent(inout) :: time(nd)           !! per device: time of the counted steps [s]
      real(dp) :: dd, hs
      integer :: q, d
      logical :: inband

      do q = 1, al%n
         associate (b => al%w(q))
            d = b%dev
            inband = st(d)%phase == phase_stick
            if (b%nin < 2) then
               b%nin = b%nin + 1
            else if (.not. (inband .or. b%band1 .or. b%band2)) then
               b%run = -1                     ! three sliding forces
            else
               ! dd = D hs, hs the two steps' mean length: divided only where it counts
               hs = 0.5_dp*(h + b%h1)
               dd = b%h1*(f(d) - b%f1) - h*(b%f1 - b%f2)
               if (abs(dd) <= b%floor4*hs) then
                  b%run = -1
               else if (b%run >= 0 .and. dd*b%d1 < 0.0_dp) then
                  b%run = b%run + 1
                  b%dmax = max(b%dmax, abs(dd)/hs)
                  b%trun = b%trun + h
               else
                  b%run = 0                   ! a run starts here
                  b%dmax = abs(dd)/hs
                  b%trun = h
               end if
               if (b%run >= alternation_run) then
                  amp(d) = max(amp(d), 0.25_dp*b%dmax)
                  time(d) = time(d) + b%trun
                  b%trun = 0.0_dp
               end if
               b%d1 = dd
            end if
            b%f2 = b%f1
            b%f1 = f(d)
            b%band2 = b%band1
            b%band1 = inband
            b%h1 = h
         end associate
      end do
   end subroutine alternation_step

end module fd_band_alternation
