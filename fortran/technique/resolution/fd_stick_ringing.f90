!> Whether dt1 resolves the ringing of the hysteretic devices' sticking springs, on which
!> their stick-slip decisions rest (Newmark technique).
!>
!> A sticking hysteretic device is a spring k = P mu / f between its two masses (eqs. 2-5):
!> a local mode of circular frequency omega = sqrt(k / m_r), m_r = m_i m_j / (m_i + m_j)
!> (m_i for a device to the table), far above the structure's modes when f is small. A
!> change of force near it (another device's transition; a velocity-law device crossing its
!> band, whose force is close to a square wave at the excitation's frequency, rich in odd
!> harmonics) sets it ringing, and little damps it: the structure's C = a0 M + a1 K has the
!> springs' K, not the devices'. Newmark integrates the mode with a frequency error (the
!> average acceleration rule: omega~ dt = 2 atan(omega dt / 2), 2.8 % low at omega dt =
!> 0.59, well inside "resolved", omega_max dt1 <= 2, of fd_mode_resolution). Over a long
!> stick phase that error takes the computed ringing out of phase with the model's, onto or
!> off a resonance with the excitation's harmonics: its amplitude is then the step's, not
!> the model's, and where it is large against the margin to P mu the step decides whether
!> and how often the device slides (docs/theory.md, section 6: 81 slides at n1 = 24 where
!> every n1 >= 48 gives none).
!>
!> Measured for each device with a sticking spring, over each of its stick phases p (sums
!> over the accepted steps, phase_statistics, which the technique calls at each accepted
!> step when a device has a sticking spring; measured at the phase's end, no allocation in
!> the loop):
!> - Phi_p = |delta| omega min(T_p, 1 / (zeta omega)), the phase (rad) by which the frequency
!>   error delta = 1 - omega~/omega of Newmark's beta and gamma at dt1 moves the ringing
!>   within the stick phase (length T_p) or within the time the mode's damping lets it last
!>   (zeta: the structure's C on the mode's shape, the velocity-law devices near it while in
!>   their band, c1 = P mu / eps on the shape, averaged over the phase, and Newmark's own
!>   damping for gamma > 1/2);
!> - A_p = sqrt(2) k rms(s') / omega, the amplitude of the ringing force (a force
!>   A sin(omega t) in the spring gives k s' = A omega cos(omega t), rms A omega / sqrt(2));
!> - M_p = P mu - max |F|, the margin to sliding (0 for a phase that ends in a slide);
!> - R_p = A_p / max(M_p, P mu / 4) where Phi_p > 1, else 0.
!> A device whose largest R_p exceeds 1 is not resolved: the step dephases a ringing of at
!> least a quarter of P mu and larger than the margin to sliding. Halving dt1 quarters delta.
!>
!> A planar bearing whose normal force N varies over the run: the sticking spring is N mu / f,
!> so the mode, its frequency error and its ringing force are taken at N_max (the stiffest
!> spring, which the step resolves worst), and the capacity P mu of the margin and of the floor
!> at N_min (the bearing nearest to sliding). A bearing that lifts off (N_min <= 0) has no
!> margin at its minimum (M_p = 0); its floor is then a quarter of N_max mu. [N_min, N_max] is
!> the range predicted before the run (a vertical component's, nrange of ringing_init) joined
!> with the bearing's N observed at the accepted states (fd_result's bearing_n_min and
!> bearing_n_max, which the overturning's dN moves beyond the prediction): the technique calls
!> ringing_normal_force after each accepted state's N is observed, and a range that grew moves
!> the watched bearing's spring, mode and capacities to it. A stick phase, measured at its end,
!> is so judged at a range that holds every N it had, and stick_freq_error at the end of the run
!> is that of the largest N of the run.
module fd_stick_ringing
   use fd_kinds, only: dp
   use fd_error, only: error_type, fmt_int, allocation_error
   use fd_model, only: model_type, device_type
   use fd_kinematics, only: moved_mass, device_nodes, devices_are_pairs, add_device, device_relative
   use fd_stiffness, only: stiffness_form
   use fd_friction, only: sticking_stiffness, law_stuck, stuck_dashpot
   use fd_device_state, only: device_state, phase_stick
   use fd_result, only: result_type, device_bearings
   implicit none
   private

   public :: ringing_type, ringing_init, ringing_changed, ringing_finish, newmark_frequency, ringing_normal_force
   public :: ringing_phase_gate, ringing_floor, stat_time, stat_sd2, stat_fmax, stat_damping

   !> Phase drift (rad) within a stick phase above which the ringing is the step's.
   real(dp), parameter :: ringing_phase_gate = 1.0_dp
   !> Margin to P mu below which a ringing is measured against this fraction of P mu.
   real(dp), parameter :: ringing_floor = 0.25_dp
   !> The rows of ringing_type's stats.
   integer, parameter :: stat_time = 1, stat_sd2 = 2, stat_fmax = 3, stat_damping = 4

   !> The devices watched, and every device's statistics of its current phase, which the
   !> technique accumulates at each accepted step (fd_newmark's phase_statistics).
   type :: ringing_type
      integer :: n = 0                          !! devices with a sticking spring
      integer, allocatable :: dev(:)            !! their numbers
      real(dp), allocatable :: k(:)             !! sticking stiffness P mu / f [N/m]
      real(dp), allocatable :: omega(:)         !! its mode's circular frequency [rad/s]
      real(dp), allocatable :: pmu(:)           !! P mu of the margin to sliding [N]
      real(dp), allocatable :: pfloor(:)        !! P mu of the floor [N]
      real(dp), allocatable :: drift(:)         !! |delta| omega: dephasing rate [rad/s]
      real(dp), allocatable :: c_fixed(:)       !! damping of the mode: the structure's C and
                                                !! Newmark's own, as 2 m_r omega zeta [N s/m]
      real(dp), allocatable :: mr(:)            !! the mode's mass m_r [kg]
      integer, allocatable :: first(:)          !! its band devices: first(q) .. first(q + 1) - 1
      integer, allocatable :: band_dev(:)       !! velocity-law devices that move with the mode
      real(dp), allocatable :: band_shape(:)    !! their (phi_i - phi_j)^2
      real(dp), allocatable :: c_start(:)       !! the band devices' damping integral on the
                                                !! mode when the stick phase began [N s2/m]
      !> per device (columns), since the start of its current phase (row 4: of the run): the
      !> phase's length [s], the integral of s'^2 dt [m2/s], the largest |F| [N], and the
      !> integral of the device's damping cs dt [N s2/m] (phase_statistics)
      real(dp), allocatable :: stats(:, :)
      integer, allocatable :: bearing(:)        !! the planar bearing of each (0: none)
      real(dp), allocatable :: nrange(:, :)     !! (2, n) the N range k, omega, pmu, pfloor are at [N]
      real(dp) :: dt1 = 0.0_dp                  !! main step [s]
      real(dp) :: beta = 0.0_dp, gamma = 0.0_dp !! Newmark's parameters
   end type ringing_type

contains

   !> Newmark's own frequency and damping of an undamped oscillator at omega dt = w: the
   !> eigenvalues of the step's amplification matrix, lambda^2 - 2 A1 lambda + A2 = 0 with
   !> A1 = 1 - w^2 (gamma + 1/2) / (2 D), A2 = 1 - w^2 (gamma - 1/2) / D, D = 1 + beta w^2.
   !> wt = arg(lambda) = omega~ dt and zeta = -ln(A2) / (2 wt); oscillating = .false. (wt = 0)
   !> when the roots are real (the step does not oscillate at all). A2 - A1^2 is taken as
   !> (w^2 / D) (1 - w^2 (gamma + 1/2)^2 / (4 D)), without the cancellation of the difference
   !> (which would cost wt all its digits at small steps).
   pure subroutine newmark_frequency(w, beta, gamma, wt, zeta, oscillating)
      real(dp), intent(in) :: w                 !! omega dt
      real(dp), intent(in) :: beta, gamma       !! Newmark's parameters
      real(dp), intent(out) :: wt               !! omega~ dt
      real(dp), intent(out) :: zeta             !! Newmark's damping ratio of the mode
      logical, intent(out) :: oscillating       !! complex roots
      real(dp) :: d, a1, a2, e

      d = 1.0_dp + beta*w*w
      a1 = 1.0_dp - w*w*(gamma + 0.5_dp)/(2.0_dp*d)
      a2 = 1.0_dp - w*w*(gamma - 0.5_dp)/d
      e = 1.0_dp - w*w*(gamma + 0.5_dp)**2/(4.0_dp*d)
      oscillating = w > 0.0_dp .and. d > 0.0_dp .and. e > 0.0_dp .and. a2 > 0.0_dp
      wt = 0.0_dp
      zeta = 0.0_dp
      if (.not. oscillating) return
      wt = atan2(w/sqrt(d)*sqrt(e), a1)
      if (gamma /= 0.5_dp) zeta = -log(a2)/(2.0_dp*wt)
   end subroutine newmark_frequency

   !> The devices with a sticking spring, their modes and Newmark's error on them at dt1
   !> (res%stick_freq_error), and the phase statistics zeroed. The springs and velocity-law
   !> devices that act on a mode are found through the nodes' incidence lists: O(elements).
   subroutine ringing_init(model, dt1, beta, gamma, a0, a1, rg, res, error, nrange)
      type(model_type), intent(in) :: model         !! the model
      real(dp), intent(in) :: dt1                   !! main step [s]
      real(dp), intent(in) :: beta, gamma           !! Newmark's parameters
      real(dp), intent(in) :: a0, a1                !! C = a0 M + a1 K (K of the springs)
      type(ringing_type), intent(out) :: rg         !! the devices watched
      type(result_type), intent(inout) :: res       !! stick_freq_error, stick_checked set
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      real(dp), intent(in), optional :: nrange(:, :) !! (2, n_devices) each device's smallest and
                                                     !! largest normal force over the run [N]
                                                     !! (absent: the deck's p throughout)
      integer, allocatable :: sp_first(:), sp_list(:), vd_first(:), vd_list(:), di(:), dj(:)
      logical, allocatable :: velocity(:)
      real(dp) :: ai, aj, c
      integer :: nd, ns, q, i, j, nb, stat, first

      res%stick_checked = .false.
      if (model%n_kx > 0 .or. .not. devices_are_pairs(model)) then
         call general_ringing_init(model, dt1, beta, gamma, a0, a1, rg, res, error)
         if (.not. allocated(error)) call watch_ranges()
         return
      end if
      call watch_springs(model, dt1, beta, gamma, rg, res, error)
      if (allocated(error)) return
      nd = model%n_devices
      ns = model%n_springs
      allocate (di(nd), dj(nd), velocity(nd), stat=stat)
      if (stat == 0) then
         call device_nodes(model, di, dj, first)
         velocity = law_stuck(model%dev(1:nd)%law) == stuck_dashpot
         call incidence(model%n_dof, model%spring_i(1:ns), model%spring_j(1:ns), [(.true., i=1, ns)], &
                        sp_first, sp_list, stat)
      end if
      if (stat == 0) call incidence(model%n_dof, di, dj, velocity, vd_first, vd_list, stat)
      ! the velocity-law devices that move with each mode: counted, then listed
      nb = 0
      if (stat == 0) then
         do q = 1, rg%n
            call mode_of(rg%dev(q))
            call band_devices(.false.)
         end do
         allocate (rg%band_dev(nb), rg%band_shape(nb), stat=stat)
      end if
      call springs_memory(rg, stat, error)
      if (stat /= 0) return
      if (rg%n == 0) return
      res%stick_checked = .true.
      nb = 0
      do q = 1, rg%n
         call mode_of(rg%dev(q))
         rg%first(q) = nb + 1
         call band_devices(.true.)
         ! the structure's damping on the mode: a0 M (a0 m_r), and a1 K of the springs at its nodes
         c = a0*rg%mr(q)
         call spring_damping(i)
         call spring_damping(j)
         rg%c_fixed(q) = c
         call spring_mode(q, rg, res)
      end do
      rg%first(rg%n + 1) = nb + 1
      call watch_ranges()
   contains
      !> The N ranges watched: an absent nrange is not handed on (gfortran 12 reads the bounds
      !> of an absent assumed-shape argument passed on to this pure routine, whether the
      !> caller's actual was absent or an unallocated array: the checked build's UBSan
      !> reports an overflow in either case)
      subroutine watch_ranges()
         if (present(nrange)) then
            call watch_normal_force(model, rg, res, nrange)
         else
            call watch_normal_force(model, rg, res)
         end if
      end subroutine watch_ranges
      !> The mode of device d: node i moves ai, node j -aj, the centre of mass stays.
      subroutine mode_of(d)
         integer, intent(in) :: d
         i = di(d)
         j = dj(d)
         ai = 1.0_dp
         aj = 0.0_dp
         if (j > 0) then
            ai = model%mass(j)/(model%mass(i) + model%mass(j))
            aj = model%mass(i)/(model%mass(i) + model%mass(j))
         end if
      end subroutine mode_of
      !> The mode's shape at a node.
      pure real(dp) function mode_shape(node)
         integer, intent(in) :: node
         mode_shape = 0.0_dp
         if (node == i .and. node > 0) mode_shape = ai
         if (node == j .and. node > 0) mode_shape = -aj
      end function mode_shape
      !> The velocity-law devices at node i or j that the mode moves: counted in nb, and
      !> listed when fill.
      subroutine band_devices(fill)
         logical, intent(in) :: fill
         integer :: node, m, e
         real(dp) :: y
         do node = 1, 2
            if (node == 2 .and. j <= 0) exit
            do m = vd_first(merge(i, j, node == 1)), vd_first(merge(i, j, node == 1) + 1) - 1
               e = vd_list(m)
               if (node == 2 .and. (di(e) == i .or. dj(e) == i)) cycle   ! seen at node i
               y = mode_shape(di(e)) - mode_shape(dj(e))
               if (y == 0.0_dp) cycle
               nb = nb + 1
               if (fill) then
                  rg%band_dev(nb) = e
                  rg%band_shape(nb) = y*y
               end if
            end do
         end do
      end subroutine band_devices
      !> a1 k (phi_i - phi_j)^2 of the springs at node (not those at node i again).
      subroutine spring_damping(node)
         integer, intent(in) :: node
         integer :: m, sp
         real(dp) :: y
         if (node <= 0) return
         do m = sp_first(node), sp_first(node + 1) - 1
            sp = sp_list(m)
            if (node == j .and. (model%spring_i(sp) == i .or. model%spring_j(sp) == i)) cycle
            y = mode_shape(model%spring_i(sp)) - mode_shape(model%spring_j(sp))
            c = c + a1*model%spring_k(sp)*y*y
         end do
      end subroutine spring_damping
   end subroutine ringing_init

   !> ringing_init for a general model (stiffness K_x, devices of any direction): the mode of
   !> device d's sticking spring is phi = m_r M^-1 b_d (b_d' phi = 1, m_r = 1 / (b_d' M^-1 b_d));
   !> its damping a0 m_r + a1 phi' K phi, its band devices the velocity-law devices e with
   !> b_e' phi /= 0 (shape (b_e' phi)^2). O(n_devices (n_dof + n_devices)).
   subroutine general_ringing_init(model, dt1, beta, gamma, a0, a1, rg, res, error)
      type(model_type), intent(in) :: model         !! the model
      real(dp), intent(in) :: dt1                   !! main step [s]
      real(dp), intent(in) :: beta, gamma           !! Newmark's parameters
      real(dp), intent(in) :: a0, a1                !! C = a0 M + a1 K
      type(ringing_type), intent(out) :: rg         !! the devices watched
      type(result_type), intent(inout) :: res       !! stick_freq_error, stick_checked set
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      real(dp), allocatable :: phi(:)
      logical, allocatable :: velocity(:)
      real(dp) :: y, ek
      integer :: nd, d, e, q, nb, pass, stat

      call watch_springs(model, dt1, beta, gamma, rg, res, error)
      if (allocated(error)) return
      nd = model%n_devices
      allocate (phi(model%n_dof), velocity(nd), stat=stat)
      call springs_memory(rg, stat, error)
      if (stat /= 0) return
      velocity = law_stuck(model%dev(1:nd)%law) == stuck_dashpot
      ! two passes: count the band devices, then list them
      do pass = 1, 2
         nb = 0
         do q = 1, rg%n
            d = rg%dev(q)
            phi = 0.0_dp
            call add_device(model, d, 1.0_dp, phi)
            phi = rg%mr(q)*phi/model%mass
            if (pass == 2) rg%first(q) = nb + 1
            do e = 1, nd
               if (.not. velocity(e)) cycle
               y = device_relative(model, e, phi)
               if (y == 0.0_dp) cycle
               nb = nb + 1
               if (pass == 2) then
                  rg%band_dev(nb) = e
                  rg%band_shape(nb) = y*y
               end if
            end do
            if (pass == 1) cycle
            ek = stiffness_form(model, phi, phi)
            rg%c_fixed(q) = a0*rg%mr(q) + a1*ek
            call spring_mode(q, rg, res)
         end do
         if (pass == 2) exit
         allocate (rg%band_dev(nb), rg%band_shape(nb), stat=stat)
         call springs_memory(rg, stat, error)
         if (stat /= 0) return
      end do
      rg%first(rg%n + 1) = nb + 1
      res%stick_checked = rg%n > 0
   end subroutine general_ringing_init

   !> The devices with a sticking spring (rg%n, rg%dev), each one's spring, the mass its mode
   !> moves, its capacities at the deck's p and its planar bearing; the step (rg%dt1, beta,
   !> gamma); the arrays of the devices watched allocated but for the band devices', and the
   !> phase statistics zeroed.
   subroutine watch_springs(model, dt1, beta, gamma, rg, res, error)
      type(model_type), intent(in) :: model         !! the model
      real(dp), intent(in) :: dt1                   !! main step [s]
      real(dp), intent(in) :: beta, gamma           !! Newmark's parameters
      type(ringing_type), intent(inout) :: rg       !! the devices watched
      type(result_type), intent(in) :: res          !! the bearings
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      integer, allocatable :: bof(:)
      real(dp) :: k
      integer :: nd, d, q, stat

      nd = model%n_devices
      rg%dt1 = dt1
      rg%beta = beta
      rg%gamma = gamma
      rg%n = count(sticking_stiffness(model%dev(1:nd)) > 0.0_dp)
      allocate (rg%dev(rg%n), rg%k(rg%n), rg%omega(rg%n), rg%pmu(rg%n), rg%pfloor(rg%n), rg%drift(rg%n), &
                rg%c_fixed(rg%n), rg%mr(rg%n), rg%first(rg%n + 1), rg%c_start(rg%n), rg%stats(4, nd), &
                rg%bearing(rg%n), rg%nrange(2, rg%n), bof(nd), stat=stat)
      call springs_memory(rg, stat, error)
      if (stat /= 0) return
      rg%stats = 0.0_dp
      rg%c_start = 0.0_dp
      call device_bearings(res, bof)
      q = 0
      do d = 1, nd
         k = sticking_stiffness(model%dev(d))
         if (.not. (k > 0.0_dp)) cycle
         q = q + 1
         rg%dev(q) = d
         rg%k(q) = k
         rg%mr(q) = moved_mass(model, d)
         rg%pmu(q) = model%dev(d)%p*model%dev(d)%mu
         rg%pfloor(q) = rg%pmu(q)
         rg%bearing(q) = bof(d)
      end do
   end subroutine watch_springs

   !> The error of the memory of the devices watched when stat (an allocation's) is not 0.
   pure subroutine springs_memory(rg, stat, error)
      type(ringing_type), intent(in) :: rg          !! the devices watched (n set)
      integer, intent(in) :: stat                   !! the allocation's status
      type(error_type), allocatable, intent(out) :: error !! not enough memory

      call allocation_error(error, stat, "the sticking springs of "//trim(fmt_int(rg%n))//" devices")
   end subroutine springs_memory

   !> Watched device q's sticking spring rg%k(q) on the mass its mode moves: the mode's
   !> frequency, Newmark's error on it at dt1 (res%stick_freq_error), the drift that makes, and
   !> Newmark's own damping of the mode added to rg%c_fixed(q).
   pure subroutine spring_mode(q, rg, res)
      integer, intent(in) :: q                      !! the watched device
      type(ringing_type), intent(inout) :: rg       !! the devices watched
      type(result_type), intent(inout) :: res       !! stick_freq_error
      real(dp) :: x, wt, zn
      integer :: d
      logical :: osc

      d = rg%dev(q)
      rg%omega(q) = sqrt(rg%k(q)/rg%mr(q))
      x = rg%omega(q)*rg%dt1
      call newmark_frequency(x, rg%beta, rg%gamma, wt, zn, osc)
      res%stick_freq_error(d) = 1.0_dp
      if (osc) res%stick_freq_error(d) = 1.0_dp - wt/x
      rg%drift(q) = abs(res%stick_freq_error(d))*rg%omega(q)
      rg%c_fixed(q) = rg%c_fixed(q) + 2.0_dp*rg%mr(q)*rg%omega(q)*zn
   end subroutine spring_mode

   !> The N range each watched device's figures are at (rg%nrange): the prediction nrange
   !> (absent: the deck's p), those that vary moved to it (ringing_at).
   pure subroutine watch_normal_force(model, rg, res, nrange)
      type(model_type), intent(in) :: model         !! the model
      type(ringing_type), intent(inout) :: rg       !! the devices watched
      type(result_type), intent(inout) :: res       !! stick_freq_error
      real(dp), intent(in), optional :: nrange(:, :) !! (2, n_devices) smallest and largest N [N]
      integer :: q, d

      do q = 1, rg%n
         d = rg%dev(q)
         rg%nrange(:, q) = model%dev(d)%p
         if (.not. present(nrange)) cycle
         rg%nrange(:, q) = nrange(:, d)
         if (nrange(1, d) < nrange(2, d)) call ringing_at(model, q, rg, res)
      end do
   end subroutine watch_normal_force

   !> The watched bearings' N ranges joined with the N observed so far (res%bearing_n_min,
   !> res%bearing_n_max, the observer's at the accepted states); a range that grew moves the
   !> device's spring, mode, frequency error and capacities to it (ringing_at). Called after
   !> each accepted state's normal forces are observed; no allocation.
   pure subroutine ringing_normal_force(model, rg, res)
      type(model_type), intent(in) :: model         !! the model
      type(ringing_type), intent(inout) :: rg       !! the devices watched
      type(result_type), intent(inout) :: res       !! stick_freq_error
      real(dp) :: lo, hi
      integer :: q, b

      do q = 1, rg%n
         b = rg%bearing(q)
         if (b == 0) cycle
         lo = min(rg%nrange(1, q), res%bearing_n_min(b))
         hi = max(rg%nrange(2, q), res%bearing_n_max(b))
         if (.not. (lo < rg%nrange(1, q) .or. hi > rg%nrange(2, q))) cycle
         rg%nrange(1, q) = lo
         rg%nrange(2, q) = hi
         call ringing_at(model, q, rg, res)
      end do
   end subroutine ringing_normal_force

   !> Watched device q at its N range rg%nrange(:, q) (smallest below largest): the sticking
   !> spring, its mode's frequency, Newmark's error on it (res%stick_freq_error), its drift and
   !> Newmark's own damping of it at the largest N; the margin's P mu at the smallest (0 when
   !> the bearing lifts off), the floor's there too unless it lifts off (then at the largest).
   pure subroutine ringing_at(model, q, rg, res)
      type(model_type), intent(in) :: model         !! the model
      integer, intent(in) :: q                      !! the watched device
      type(ringing_type), intent(inout) :: rg       !! the devices watched
      type(result_type), intent(inout) :: res       !! stick_freq_error
      type(device_type) :: dv
      real(dp) :: zn0, wt0
      integer :: d
      logical :: osc

      d = rg%dev(q)
      dv = model%dev(d)
      dv%p = max(rg%nrange(2, q), 0.0_dp)
      ! Newmark's own damping of the mode it had out of c_fixed, that of N_max's in
      call newmark_frequency(rg%omega(q)*rg%dt1, rg%beta, rg%gamma, wt0, zn0, osc)
      rg%c_fixed(q) = rg%c_fixed(q) - 2.0_dp*rg%mr(q)*rg%omega(q)*zn0
      rg%k(q) = sticking_stiffness(dv)
      call spring_mode(q, rg, res)
      rg%pmu(q) = max(rg%nrange(1, q), 0.0_dp)*model%dev(d)%mu
      rg%pfloor(q) = rg%pmu(q)
      if (.not. rg%pfloor(q) > 0.0_dp) rg%pfloor(q) = dv%p*model%dev(d)%mu
   end subroutine ringing_at

   !> The elements at each node 1..n (node 0, the table, left out) of those with use: the
   !> elements at node m are list(first(m) : first(m + 1) - 1); one entry when both ends
   !> are the same node.
   pure subroutine incidence(n, ei, ej, use, first, list, stat)
      integer, intent(in) :: n                      !! nodes
      integer, intent(in) :: ei(:), ej(:)           !! the elements' end nodes
      logical, intent(in) :: use(:)                 !! the elements listed
      integer, allocatable, intent(out) :: first(:), list(:)
      integer, intent(out) :: stat                  !! allocation status
      integer :: e, m

      allocate (first(n + 2), stat=stat)
      if (stat /= 0) return
      first = 0
      do e = 1, size(ei)
         if (.not. use(e)) cycle
         if (ei(e) > 0) first(ei(e) + 2) = first(ei(e) + 2) + 1
         if (ej(e) > 0 .and. ej(e) /= ei(e)) first(ej(e) + 2) = first(ej(e) + 2) + 1
      end do
      first(1) = 1
      first(2) = 1
      do m = 3, n + 2
         first(m) = first(m) + first(m - 1)
      end do
      allocate (list(max(first(n + 2) - 1, 0)), stat=stat)
      if (stat /= 0) return
      ! first(m + 1) is the next free entry of node m while filling; then first(m) its first
      do e = 1, size(ei)
         if (.not. use(e)) cycle
         if (ei(e) > 0) then
            list(first(ei(e) + 1)) = e
            first(ei(e) + 1) = first(ei(e) + 1) + 1
         end if
         if (ej(e) > 0 .and. ej(e) /= ei(e)) then
            list(first(ej(e) + 1)) = e
            first(ej(e) + 1) = first(ej(e) + 1) + 1
         end if
      end do
   end subroutine incidence

   !> An accepted step changed phases (phase0 to phase1): the stick phases that ended are
   !> measured, those that began note their band damping, and the statistics of every device
   !> whose phase changed start again.
   subroutine ringing_changed(rg, phase0, phase1, res)
      type(ringing_type), intent(inout) :: rg       !! the devices watched
      integer, intent(in) :: phase0(:)              !! phases the step was taken in
      integer, intent(in) :: phase1(:)              !! phases after it
      type(result_type), intent(inout) :: res       !! stick_ringing_ratio, stick_ringing, stick_margin
      integer :: q, d

      do q = 1, rg%n
         d = rg%dev(q)
         if (phase0(d) == phase1(d)) cycle
         if (phase0(d) == phase_stick) call close_phase(rg, q, res)
         if (phase1(d) == phase_stick) rg%c_start(q) = band_damping(rg, q)
      end do
      do d = 1, size(phase0)
         if (phase0(d) == phase1(d)) cycle
         rg%stats(stat_time:stat_fmax, d) = 0.0_dp
      end do
   end subroutine ringing_changed

   !> The end of the run: the stick phases still open measured (the verdict: fd_warnings).
   subroutine ringing_finish(rg, phase, res)
      type(ringing_type), intent(inout) :: rg       !! the devices watched
      integer, intent(in) :: phase(:)               !! the phases at the end
      type(result_type), intent(inout) :: res       !! the result
      integer :: q

      if (rg%n == 0) return
      do q = 1, rg%n
         if (phase(rg%dev(q)) == phase_stick) call close_phase(rg, q, res)
      end do
   end subroutine ringing_finish

   !> The damping integral of watched device q's band devices on its mode.
   pure real(dp) function band_damping(rg, q) result(c)
      type(ringing_type), intent(in) :: rg
      integer, intent(in) :: q
      integer :: b

      c = 0.0_dp
      do b = rg%first(q), rg%first(q + 1) - 1
         c = c + rg%stats(stat_damping, rg%band_dev(b))*rg%band_shape(b)
      end do
   end function band_damping

   !> Measure the stick phase of watched device q, which has just ended.
   subroutine close_phase(rg, q, res)
      type(ringing_type), intent(in) :: rg
      integer, intent(in) :: q
      type(result_type), intent(inout) :: res
      real(dp) :: t, amp, margin, ratio, c, t_mem
      integer :: d

      d = rg%dev(q)
      t = rg%stats(stat_time, d)
      if (.not. (t > 0.0_dp)) return
      ! the time the ringing lasts: the phase, or 1 / (zeta omega) = 2 m_r / c
      c = rg%c_fixed(q) + (band_damping(rg, q) - rg%c_start(q))/t
      t_mem = t
      if (c > 0.0_dp) t_mem = min(t, 2.0_dp*rg%mr(q)/c)
      if (.not. (rg%drift(q)*t_mem > ringing_phase_gate)) return
      amp = sqrt(2.0_dp*rg%stats(stat_sd2, d)/t)*rg%k(q)/rg%omega(q)
      margin = max(rg%pmu(q) - rg%stats(stat_fmax, d), 0.0_dp)
      ratio = amp/max(margin, ringing_floor*rg%pfloor(q))
      if (ratio > res%stick_ringing_ratio(d)) then
         res%stick_ringing_ratio(d) = ratio
         res%stick_ringing(d) = amp
         res%stick_margin(d) = margin
      end if
   end subroutine close_phase

end module fd_stick_ringing
