!> The limits of Newmark's step control (docs/namelist.md, "&integration", "Limits of the step
!> control"): what keeps the work of a step refinement bounded and every step meaningful.
!>
!> - A dt1 step is refined into at most max_refinement steps: n2 * 2**L, L the halvings from
!>   dt2 down to dt_min (checked when the deck is read).
!> - A stiffness joining two DOFs (a spring, a sticking device) is at most
!>   max_stiffness_ratio times the inertia of its masses at dt1 (checked when the deck is read):
!>   beyond, the factorization of the effective stiffness loses all its digits.
!> - A sliding device whose band (eps, eps1) is narrower than the velocity change its friction
!>   force makes in the finest step, P mu dt_min / m, cannot be resolved by any step: when such
!>   a device still violates the correctness condition at dt_min the run stops with an error
!>   (checked while integrating: a device that never slides, however narrow its band, is fine).
module fd_step_limits
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real
   use fd_model, only: model_type, integration_type, device_parameter
   use fd_friction, only: sticking_stiffness, sticking_damping, friction_capacity, law_band, law_band_name, &
                          law_coupling_name
   use fd_kinematics, only: moved_mass, pair_nodes
   use fd_excitation, only: excitation_type
   implicit none
   private

   public :: max_refinement, max_stiffness_ratio, halving_levels, finest_step, band_floor, band_of
   public :: check_step_limits, unresolved_band, max_nested, nested_splits, max_settle, max_follow, follow_tol

   !> Most Newmark steps one dt1 step may be refined into: n2 steps dt2, each halved L times.
   integer, parameter :: max_refinement = 2**20
   !> Largest ratio k beta dt1**2 / (m_i + m_j) of a stiffness joining two DOFs to the inertia
   !> of its masses in the effective stiffness: beyond, the factorization loses more than 12
   !> of the 16 digits of double precision.
   real(dp), parameter :: max_stiffness_ratio = 1.0e12_dp
   !> Most levels of nested refinement: the prime factors of n2 <= 2**20.
   integer, parameter :: max_nested = 20
   !> Most trials of a dt1 step in the phases it ends in (`refinement = 'implicit'`) before the
   !> step is refined as the paper's instead.
   integer, parameter :: max_settle = 8

   !> Most passes of the fixed point on the sliding forces of a speed-dependent mu within one
   !> step (each a solve with the step's factor); beyond, the step is refined as for a
   !> violation of the correctness condition, and counted when it is accepted unconverged.
   integer, parameter :: max_follow = 50
   !> A pass has converged when no followed force changes by more than follow_tol times the
   !> device's capacity P mu_largest.
   real(dp), parameter :: follow_tol = 1.0e-10_dp

contains

   !> Number of halvings from sub down to dt_min (at most 30).
   pure integer function halving_levels(sub, dt_min) result(lmax)
      real(dp), intent(in) :: sub     !! the step halved [s]
      real(dp), intent(in) :: dt_min  !! the floor [s]

      lmax = 0
      do while (lmax < 30 .and. sub/2.0_dp**(lmax + 1) >= dt_min*(1.0_dp - 1.0e-12_dp))
         lmax = lmax + 1
      end do
   end function halving_levels

   !> The levels of nested refinement (`refinement = 'nested'`): the prime factors of n2,
   !> smallest first, so that dt1 / splits(1) / ... / splits(levels) = dt2. A prime n2 gives
   !> one level, the paper's refinement; n2 = 1 none.
   pure subroutine nested_splits(n2, splits, levels)
      integer, intent(in) :: n2                   !! dt1 / dt2, 1 .. 2**20
      integer, intent(out) :: splits(max_nested)  !! ratio of each level to the next finer one
      integer, intent(out) :: levels              !! number of levels
      integer :: m, p

      splits = 1
      levels = 0
      m = n2
      p = 2
      do while (m > 1 .and. levels < max_nested)
         if (p*p > m) then
            ! what is left is prime
            levels = levels + 1
            splits(levels) = m
            exit
         end if
         if (mod(m, p) == 0) then
            levels = levels + 1
            splits(levels) = p
            m = m/p
         else
            p = p + 1
         end if
      end do
   end subroutine nested_splits

   !> The floor of the step halving: dt_min, or dt2 / 2**10 when it is 0.
   pure real(dp) function finest_step(exc, opts) result(dt_min)
      type(excitation_type), intent(in) :: exc    !! the table motion (dt_record)
      type(integration_type), intent(in) :: opts  !! n1, n2, dt_min

      dt_min = opts%dt_min
      if (dt_min <= 0.0_dp) dt_min = exc%dt_record/opts%n1/opts%n2/2.0_dp**10
   end function finest_step

   !> The band of device d's law: eps (velocity law), eps1 (hysteretic law), 0 for a law
   !> without one (fd_friction's law_band).
   pure real(dp) function band_of(model, d) result(band)
      type(model_type), intent(in) :: model  !! the model
      integer, intent(in) :: d               !! the device

      band = law_band(model%dev(d))
   end function band_of

   !> P mu dt_min / m: the velocity change device d's friction force makes in the step dt_min
   !> on the mass it moves (m_i to the table, m_i m_j / (m_i + m_j) between two DOFs); mu the
   !> largest of a speed-dependent mu.
   pure real(dp) function band_floor(model, d, dt_min) result(floor)
      type(model_type), intent(in) :: model  !! the model
      integer, intent(in) :: d               !! the device
      real(dp), intent(in) :: dt_min         !! the finest step [s]

      floor = friction_capacity(model%dev(d))*dt_min/moved_mass(model, d)
   end function band_floor

   !> The limits checked when the deck is read: the work of a refinement, the digits of the
   !> effective stiffness. Messages start with "group &...": the deck reader prefixes the deck.
   subroutine check_step_limits(model, exc, opts, error)
      type(model_type), intent(in) :: model         !! the model
      type(excitation_type), intent(in) :: exc      !! the table motion
      type(integration_type), intent(in) :: opts    !! Newmark's settings
      type(error_type), allocatable, intent(out) :: error !! the first limit broken
      real(dp) :: dt1, dt2, kd, ratio
      integer :: levels, d, s, i, j
      character(len=:), allocatable :: var, idx

      dt1 = exc%dt_record/opts%n1
      dt2 = dt1/opts%n2
      levels = 0
      if (opts%check) levels = halving_levels(dt2, finest_step(exc, opts))
      if (opts%n2 > max_refinement) then
         call fatal_error(error, "group &integration: n2 = "//trim(fmt_int(opts%n2))//" is invalid: must be at most "// &
                          trim(fmt_int(max_refinement))//": a dt1 step is refined into at most that many steps")
         return
      end if
      if (real(opts%n2, dp)*2.0_dp**levels > max_refinement) then
         call fatal_error(error, "group &integration: dt_min = "//trim(fmt_real(opts%dt_min))//" is invalid: must be "// &
                          "such that n2 * 2**L <= "//trim(fmt_int(max_refinement))//", L the halvings from dt2 = "// &
                          trim(fmt_real(dt2))//" s down to dt_min (here n2 = "//trim(fmt_int(opts%n2))//", L = "// &
                          trim(fmt_int(levels))//"): a dt1 step is refined into at most that many steps; raise dt_min "// &
                          "or lower n2")
         return
      end if
      do d = 1, model%n_devices
         ! a device between two DOFs (one on the table adds to a diagonal alone)
         call pair_nodes(model, d, i, j)
         if (i > 0 .and. j <= 0) cycle
         ! the sticking spring, or the sticking dashpot in the effective stiffness (the band's
         ! coupling P mu(eps) / eps, a speed-dependent mu at eps); a law has one or neither
         kd = sticking_stiffness(model%dev(d)) + opts%gamma/(opts%beta*dt1)*sticking_damping(model%dev(d))
         if (i > 0) then
            ratio = kd*opts%beta*dt1**2/(model%mass(i) + model%mass(j))
         else
            ! a device of any direction: against the mass it moves, 1 / (b' M^-1 b)
            ratio = kd*opts%beta*dt1**2/moved_mass(model, d)
         end if
         if (ratio > max_stiffness_ratio) then
            ! the variable named only here: fmt_real's shortest round trip costs about
            ! 4e5 instructions, 0.1 s a 1000 devices when it was built for every device
            idx = '('//trim(fmt_int(d))//')'
            var = trim(law_coupling_name(model%dev(d)%law))
            var = var//idx//' = '//trim(fmt_real(device_parameter(model%dev(d), var)))
            call fatal_error(error, "group &friction: "//var//" is invalid: the sticking stiffness of device "// &
                             trim(fmt_int(d))//", "//trim(fmt_real(kd))//" N/m in the effective stiffness at dt1 = "// &
                             trim(fmt_real(dt1))//" s, must stay within "//trim(fmt_real(max_stiffness_ratio))// &
                             " times the inertia of its masses, (m_i + m_j) / (beta dt1**2) (here "// &
                             trim(fmt_real(ratio))//" times): beyond, the factorization loses all its digits; "// &
                             "raise it, or raise n1 in &integration")
            return
         end if
      end do
      do s = 1, model%n_springs
         i = model%spring_i(s); j = model%spring_j(s)
         if (j <= 0) cycle
         ratio = model%spring_k(s)*opts%beta*dt1**2/(model%mass(i) + model%mass(j))
         if (ratio > max_stiffness_ratio) then
            call fatal_error(error, "group &springs: k("//trim(fmt_int(s))//") = "//trim(fmt_real(model%spring_k(s)))// &
                             " is invalid: must stay within "//trim(fmt_real(max_stiffness_ratio))//" times the "// &
                             "inertia of its masses at the step dt1 = "//trim(fmt_real(dt1))//" s, (m_i + m_j) / "// &
                             "(beta dt1**2) (here "//trim(fmt_real(ratio))//" times): beyond, the factorization "// &
                             "loses all its digits; lower it, or raise n1 in &integration")
            return
         end if
      end do
   end subroutine check_step_limits

   !> The error for device d, sliding and still violating the correctness condition at the
   !> finest step dt_min at time t, when its band is below band_floor: no step resolves it.
   !> No error (not allocated) when the band is wide enough: the violation is then counted.
   pure subroutine unresolved_band(model, d, t, dt_min, error)
      type(model_type), intent(in) :: model         !! the model
      integer, intent(in) :: d                      !! the device violating the condition
      real(dp), intent(in) :: t                     !! end of the step [s]
      real(dp), intent(in) :: dt_min                !! the finest step [s]
      type(error_type), allocatable, intent(out) :: error !! the band cannot be resolved
      real(dp) :: floor, band
      character(len=:), allocatable :: var

      band = band_of(model, d)
      floor = band_floor(model, d, dt_min)
      if (.not. band < floor) return
      var = trim(law_band_name(model%dev(d)%law))//'('//trim(fmt_int(d))//')'
      call fatal_error(error, "group &friction: "//var//" = "//trim(fmt_real(band))//" is invalid: device "// &
                       trim(fmt_int(d))//" slides and violates the correctness condition at t = "//trim(fmt_real(t))// &
                       " s even in the finest step dt_min = "//trim(fmt_real(dt_min))//" s, and its band is narrower "// &
                       "than the velocity change its friction force makes in that step, P mu dt_min / m = "// &
                       trim(fmt_real(floor))//" m/s (m = "//trim(fmt_real(moved_mass(model, d)))//" kg, the mass it "// &
                       "moves): no step can resolve it; widen "//var//" to at least that, or lower dt_min in "// &
                       "&integration")
   end subroutine unresolved_band

end module fd_step_limits
