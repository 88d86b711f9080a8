!> Elastic vertical supports of planar bearings (`kv` > 0 of `&bearings`): each bearing's share
!> m = P / g of the mass it carries stands on its own vertical spring kv with a dashpot
!> c = 2 zeta_v sqrt(kv m), a vertical oscillator under the ground's vertical acceleration a_z
!> (upward positive). With z the compression beyond the static one (p / kv),
!>   m z'' + c z' + kv z = m a_z,   N = P + kv z + c z'   (in contact),
!> and N = 0 in flight: the support cannot pull, so where P + kv z + c z' falls to 0 the mass
!> lifts off and flies, m z'' = m (a_z + g) (its absolute acceleration -g), until it lands,
!> where P + kv z + c min(z', 0) comes back to 0 (the spring's free end reached, z = -p / kv,
!> when zeta_v = 0). The vertical motion does not depend on the horizontal one (small
!> displacements), so the technique advances it over each of its steps by the exact step map
!> of the oscillator for a_z linear in the step (fd_spectrum's exact_step_map, cached per step
!> size) and in flight by the closed form of the free fall; lift-off and landing are located
!> within a step by bisection to round-off. A step longer than 1/20 of the vertical period is
!> cut into equal parts, at whose ends lift-off is looked for (docs/theory.md, 5.7).
!>
!> A technique keeps the state at its accepted time (z, zd, fly) and computes a trial at the
!> end of a step from it (support_advance), which support_accept makes the accepted one. The
!> bearings' N then enters the laws as the rigid support's does: through each component's p
!> (support_forces). The vertical energies (kinetic, the support's and gravity's potential, the
!> ground's work and the dashpot's dissipation) join the run's energy balance.
module fd_vertical_support
   use fd_kinds, only: dp
   use fd_model, only: device_type
   use fd_spectrum, only: exact_step_map
   implicit none
   private

   public :: vertical_support, support_setup, support_advance, support_accept, support_forces, &
                supported_normal_forces, &
             support_normal_force, support_energy

   real(dp), parameter :: g = 9.80665_dp                  !! standard gravity [m/s2]
   real(dp), parameter :: pi = 3.14159265358979323846_dp
   !> parts of a step per vertical period at least (lift-off looked for at their ends)
   integer, parameter :: parts_per_period = 20
   !> halvings that locate a lift-off or a landing (an interval of 2^-80 of the part: round-off)
   integer, parameter :: bisections = 80
   !> events (lift-off, landing) a part may hold before the rest of it is taken as it is
   integer, parameter :: max_events = 8

   !> The elastic supports of a model's bearings, their accepted and trial states.
   type :: vertical_support
      integer :: nb = 0                                   !! bearings on an elastic support
      integer, allocatable :: dev(:)                      !! (nb) each one's x component
      integer, allocatable :: bearing(:)                  !! (nb) its number among the bearings
      real(dp), allocatable :: m(:), k(:), c(:), p(:), wn(:)  !! (nb) mass, kv, c, P, sqrt(kv / m)
      real(dp) :: t = 0.0_dp, t1 = 0.0_dp                 !! accepted and trial times [s]
      real(dp), allocatable :: z(:), zd(:), z1(:), zd1(:) !! (nb) compression beyond the static [m], rate
      logical, allocatable :: fly(:), fly1(:)             !! (nb) in flight (N = 0)
      real(dp), allocatable :: gap(:), gap1(:)            !! (nb) peak uplift so far [m]
      integer, allocatable :: flights(:), flights1(:)     !! (nb) lift-offs so far
      real(dp), allocatable :: first(:), first1(:)        !! (nb) the first lift-off's time [s]
      real(dp), allocatable :: air(:), air1(:)            !! (nb) time in flight so far [s]
      real(dp) :: w_in1 = 0.0_dp                          !! the trial step's ground work [J]
      real(dp) :: w_damp1 = 0.0_dp                        !! the trial step's dissipation [J]
      real(dp), allocatable :: hs(:, :)                   !! (nslot, nb) step of a cached map [s]
      integer, allocatable :: np(:, :)                    !! (nslot, nb) its parts
      real(dp), allocatable :: maps(:, :, :)              !! (8, nslot, nb) phi, g0, g1 of a part
   end type vertical_support

contains

   !> The elastic supports of the model's bearings (devices with a partner, component 1, kv > 0),
   !> at rest on their static compression; nslot step sizes whose maps are kept. Allocates.
   subroutine support_setup(nd, dev, nslot, vs, stat)
      integer, intent(in) :: nd                     !! devices
      type(device_type), intent(in) :: dev(nd)      !! the devices as the deck made them
      integer, intent(in) :: nslot                  !! step sizes kept (the technique's levels)
      type(vertical_support), intent(out) :: vs     !! the supports
      integer, intent(out) :: stat                  !! allocation status
      integer :: d, b, i

      vs%nb = 0
      do d = 1, nd
         if (dev(d)%partner > 0 .and. dev(d)%component == 1 .and. dev(d)%kv > 0.0_dp) vs%nb = vs%nb + 1
      end do
      allocate (vs%dev(vs%nb), vs%bearing(vs%nb), vs%m(vs%nb), vs%k(vs%nb), vs%c(vs%nb), vs%p(vs%nb), &
                vs%wn(vs%nb), vs%z(vs%nb), vs%zd(vs%nb), vs%z1(vs%nb), vs%zd1(vs%nb), vs%fly(vs%nb), &
                vs%fly1(vs%nb), vs%gap(vs%nb), vs%gap1(vs%nb), vs%flights(vs%nb), vs%flights1(vs%nb), &
                vs%first(vs%nb), vs%first1(vs%nb), vs%air(vs%nb), vs%air1(vs%nb), vs%hs(max(nslot, 1), vs%nb), &
                vs%np(max(nslot, 1), vs%nb), vs%maps(8, max(nslot, 1), vs%nb), stat=stat)
      if (stat /= 0) return
      b = 0
      i = 0
      do d = 1, nd
         if (dev(d)%partner == 0 .or. dev(d)%component /= 1) cycle
         b = b + 1
         if (.not. dev(d)%kv > 0.0_dp) cycle
         i = i + 1
         vs%dev(i) = d
         vs%bearing(i) = b
         vs%p(i) = dev(d)%p_static
         vs%m(i) = dev(d)%p_static/g
         vs%k(i) = dev(d)%kv
         vs%wn(i) = sqrt(dev(d)%kv/vs%m(i))
         vs%c(i) = 2.0_dp*dev(d)%zeta_v*sqrt(dev(d)%kv*vs%m(i))
      end do
      vs%z = 0.0_dp; vs%zd = 0.0_dp; vs%z1 = 0.0_dp; vs%zd1 = 0.0_dp
      vs%fly = .false.; vs%fly1 = .false.
      vs%gap = 0.0_dp; vs%gap1 = 0.0_dp
      vs%flights = 0; vs%flights1 = 0
      vs%first = 0.0_dp; vs%first1 = 0.0_dp
      vs%air = 0.0_dp; vs%air1 = 0.0_dp
      vs%hs = -1.0_dp
      vs%np = 1
      vs%maps = 0.0_dp
      vs%t = 0.0_dp
      vs%t1 = 0.0_dp
   end subroutine support_setup

   !> The trial state at t1 from the accepted one (at vs%t) under a_z linear from a0 (at vs%t)
   !> to a1 (at t1); slot: the step size's cache (1..nslot; the maps of the last step of that
   !> slot's size are kept). The trial's ground work and dissipation into w_in1, w_damp1.
   pure subroutine support_advance(vs, slot, t1, a0, a1)
      type(vertical_support), intent(inout) :: vs
      integer, intent(in) :: slot                   !! the step size's cache
      real(dp), intent(in) :: t1                    !! the step's end [s]
      real(dp), intent(in) :: a0, a1                !! a_z at the step's start and end [m/s2]
      real(dp) :: h, hp, aa, ab, z, zd, gap, w_in, w_damp, map(8)
      integer :: i, j, s
      logical :: fly

      vs%t1 = t1
      vs%w_in1 = 0.0_dp
      vs%w_damp1 = 0.0_dp
      h = t1 - vs%t
      s = min(max(slot, 1), size(vs%hs, 1))
      do i = 1, vs%nb
         z = vs%z(i)
         zd = vs%zd(i)
         fly = vs%fly(i)
         gap = vs%gap(i)
         vs%flights1(i) = vs%flights(i)
         vs%first1(i) = vs%first(i)
         vs%air1(i) = vs%air(i)
         if (h > 0.0_dp) then
            if (vs%hs(s, i) /= h) then
               ! the map of a part of this step size
               vs%np(s, i) = max(1, ceiling(parts_per_period*h*vs%wn(i)/(2.0_dp*pi)))
               vs%hs(s, i) = h
               call part_map(vs%wn(i), vs%c(i)/vs%m(i), h/vs%np(s, i), map)
               vs%maps(:, s, i) = map
            end if
            hp = h/vs%np(s, i)
            do j = 1, vs%np(s, i)
               aa = a0 + (a1 - a0)*real(j - 1, dp)/vs%np(s, i)
               ab = a0 + (a1 - a0)*real(j, dp)/vs%np(s, i)
               map = vs%maps(:, s, i)
               call advance_part(vs, i, vs%t + (j - 1)*hp, hp, aa, ab, map, z, zd, fly, gap, w_in, w_damp)
               vs%w_in1 = vs%w_in1 + w_in
               vs%w_damp1 = vs%w_damp1 + w_damp
            end do
         end if
         vs%z1(i) = z
         vs%zd1(i) = zd
         vs%fly1(i) = fly
         vs%gap1(i) = gap
      end do
   end subroutine support_advance

   !> The trial state becomes the accepted one.
   pure subroutine support_accept(vs)
      type(vertical_support), intent(inout) :: vs

      vs%t = vs%t1
      vs%z = vs%z1
      vs%zd = vs%zd1
      vs%fly = vs%fly1
      vs%gap = vs%gap1
      vs%flights = vs%flights1
      vs%first = vs%first1
      vs%air = vs%air1
   end subroutine support_accept

   !> Support i's normal force (its oscillator's, before the overturning) at the accepted state
   !> (trial = .false.) or the trial's end (.true.): P + kv z + c z' in contact, 0 in flight [N].
   elemental real(dp) function support_normal_force(vs, i, trial) result(n)
      type(vertical_support), intent(in) :: vs
      integer, intent(in) :: i                      !! the support (1..nb)
      logical, intent(in) :: trial                  !! at the trial's end

      if (trial) then
         n = 0.0_dp
         if (.not. vs%fly1(i)) n = vs%p(i) + vs%k(i)*vs%z1(i) + vs%c(i)*vs%zd1(i)
      else
         n = 0.0_dp
         if (.not. vs%fly(i)) n = vs%p(i) + vs%k(i)*vs%z(i) + vs%c(i)*vs%zd(i)
      end if
   end function support_normal_force

   !> Each bearing on an elastic support's normal force at the accepted state into pn (by
   !> bearing): its oscillator's, plus the overturning's dn when tilt (dn then present) and it
   !> is in contact (in flight N = 0 whatever the overturning). Other bearings' pn stay.
   pure subroutine supported_normal_forces(vs, tilt, pn, dn)
      type(vertical_support), intent(in) :: vs
      logical, intent(in) :: tilt                   !! the overturning's dN is added
      real(dp), intent(inout) :: pn(:)              !! (bearings) normal forces [N]
      real(dp), intent(in), optional :: dn(:)       !! the overturning's dN per bearing [N] (with tilt)
      integer :: i, b

      do i = 1, vs%nb
         b = vs%bearing(i)
         pn(b) = support_normal_force(vs, i, .false.)
         if (tilt .and. .not. vs%fly(i)) pn(b) = pn(b) + dn(b)
      end do
   end subroutine supported_normal_forces

   !> The bearings on elastic supports in dev (the copies the laws take): each component's
   !> p = max(N, 0) with N = (1 - mix) N(accepted) + mix N(trial) (mix = 0: the accepted state,
   !> 1: the trial's end, theta: a step's theta point), plus the overturning's dn(b) weighted
   !> likewise by the ends in contact (in flight N = 0 whatever the overturning).
   pure subroutine support_forces(vs, mix, nd, dev, dn)
      type(vertical_support), intent(in) :: vs
      real(dp), intent(in) :: mix                   !! weight of the trial's end
      integer, intent(in) :: nd                     !! devices
      type(device_type), intent(inout) :: dev(nd)   !! the devices' copies, p set
      real(dp), intent(in), optional :: dn(:)       !! the overturning's dN per bearing [N]
      real(dp) :: n, wc
      integer :: i, d

      do i = 1, vs%nb
         d = vs%dev(i)
         n = 0.0_dp
         if (mix /= 1.0_dp) n = (1.0_dp - mix)*support_normal_force(vs, i, .false.)
         if (mix /= 0.0_dp) n = n + mix*support_normal_force(vs, i, .true.)
         if (present(dn)) then
            wc = 0.0_dp
            if (mix /= 1.0_dp .and. .not. vs%fly(i)) wc = 1.0_dp - mix
            if (mix /= 0.0_dp .and. .not. vs%fly1(i)) wc = wc + mix
            n = n + wc*dn(vs%bearing(i))
         end if
         dev(d)%p = max(n, 0.0_dp)
         dev(d + 1)%p = dev(d)%p
      end do
   end subroutine support_forces

   !> The supports' kinetic energy sum m z'^2 / 2 and potential energy (the spring's beyond the
   !> static compression and gravity's: kv z^2 / 2 while the spring is compressed, z >= -p / kv,
   !> and -P z - P p / (2 kv) beyond its free end) at the accepted state [J].
   pure subroutine support_energy(vs, e_kin, e_pot)
      type(vertical_support), intent(in) :: vs
      real(dp), intent(out) :: e_kin, e_pot
      real(dp) :: ek, ep
      integer :: i

      e_kin = 0.0_dp
      e_pot = 0.0_dp
      do i = 1, vs%nb
         call energy_of(vs, i, vs%z(i), vs%zd(i), ek, ep)
         e_kin = e_kin + ek
         e_pot = e_pot + ep
      end do
   end subroutine support_energy

   ! ---------------------------------------------------------------- kernels

   !> The exact map of a part of length hp into map: phi (4), g0 (2), g1 (2).
   pure subroutine part_map(wn, cm, hp, map)
      real(dp), intent(in) :: wn, cm, hp
      real(dp), intent(out) :: map(8)
      real(dp) :: phi(2, 2), g0(2), g1(2)

      call exact_step_map(wn, cm, hp, phi, g0, g1)
      map(1:4) = reshape(phi, [4])
      map(5:6) = g0
      map(7:8) = g1
   end subroutine part_map

   !> Support i over a part of length hp (a_z from aa to ab): in contact by the map, in flight
   !> by the free fall, lift-off and landing located within it; the state, the peak uplift, the
   !> ground's work and the dissipation of the part.
   pure subroutine advance_part(vs, i, t0, hp, aa, ab, map, z, zd, fly, gap, w_in, w_damp)
      type(vertical_support), intent(inout) :: vs
      integer, intent(in) :: i
      real(dp), intent(in) :: t0                    !! the part's start [s]
      real(dp), intent(in) :: hp, aa, ab, map(8)
      real(dp), intent(inout) :: z, zd, gap
      logical, intent(inout) :: fly
      real(dp), intent(out) :: w_in, w_damp
      real(dp) :: tau, left, a_s, a_e, z0, zd0, z2, zd2, ek0, ep0, ek1, ep1, w, mp(8)
      integer :: e
      logical :: full

      w_in = 0.0_dp
      w_damp = 0.0_dp
      left = hp
      a_s = aa
      do e = 0, max_events
         if (.not. left > 0.0_dp) exit
         a_e = ab
         z0 = z
         zd0 = zd
         full = left == hp
         if (.not. fly) then
            ! contact: the map of the rest of the part (the cached one for a whole part)
            mp = map
            if (.not. full) call part_map(vs%wn(i), vs%c(i)/vs%m(i), left, mp)
            call contact_at(mp, z0, zd0, a_s, a_e, z2, zd2)
            tau = left
            if (e < max_events .and. state_left(vs, i, fly, z2, zd2)) then
               ! lift-off within: the force's root
               tau = state_change(vs, i, fly, z0, zd0, a_s, a_e, left)
               a_e = a_s + (ab - a_s)*tau/left
               call part_map(vs%wn(i), vs%c(i)/vs%m(i), tau, mp)
               call contact_at(mp, z0, zd0, a_s, a_e, z2, zd2)
               fly = .true.
               vs%flights1(i) = vs%flights1(i) + 1
               if (vs%flights1(i) == 1) vs%first1(i) = t0 + (hp - left) + tau
            end if
            ! the ground's work: int a z' = a_s dz + (a_e - a_s) (z2 - int z / tau), int z from
            ! the oscillator's equation integrated over the piece
            w = vs%m(i)*0.5_dp*tau*(a_s + a_e) - vs%m(i)*(zd2 - zd0) - vs%c(i)*(z2 - z0)
            w = vs%m(i)*(a_s*(z2 - z0) + (a_e - a_s)*(z2 - w/(vs%k(i)*tau)))
         else
            ! flight: the free fall z'' = a_z + g
            call flight_at(z0, zd0, a_s, a_e, left, left, z2, zd2)
            tau = left
            if (e < max_events .and. state_left(vs, i, fly, z2, zd2)) then
               ! landing within
               tau = state_change(vs, i, fly, z0, zd0, a_s, a_e, left)
               call flight_at(z0, zd0, a_s, a_e, left, tau, z2, zd2)
               a_e = a_s + (ab - a_s)*tau/left
               fly = .false.
            end if
            call flight_peak(vs%p(i)/vs%k(i), z0, zd0, a_s, ab, left, tau, gap)
            vs%air1(i) = vs%air1(i) + tau
            ! int z over the piece in closed form
            w = z0*tau + zd0*tau**2/2.0_dp + (g + a_s)*tau**3/6.0_dp + (ab - a_s)*tau**4/(24.0_dp*left)
            w = vs%m(i)*(a_s*(z2 - z0) + (a_e - a_s)*(z2 - w/tau))
         end if
         w_in = w_in + w
         if (vs%c(i) > 0.0_dp) then
            ! the dashpot's (and, in a flight from a compressed spring, the clipped force's) work:
            ! the balance of the exact piece
            call energy_of(vs, i, z0, zd0, ek0, ep0)
            call energy_of(vs, i, z2, zd2, ek1, ep1)
            w_damp = w_damp + w - (ek1 + ep1 - ek0 - ep0)
         end if
         z = z2
         zd = zd2
         left = left - tau
         a_s = a_e
         if (fly) gap = max(gap, -(z + vs%p(i)/vs%k(i)))
      end do
   end subroutine advance_part

   !> Whether support i at (z, zd) has left the state it was in: lifted off when in contact (fly
   !> false; P + kv z + c z' < 0), landed when in flight (P + kv z + c min(z', 0) >= 0).
   pure logical function state_left(vs, i, fly, z, zd) result(left)
      type(vertical_support), intent(in) :: vs
      integer, intent(in) :: i
      logical, intent(in) :: fly                    !! in flight before
      real(dp), intent(in) :: z, zd                 !! the state [m], [m/s]

      if (fly) then
         left = vs%p(i) + vs%k(i)*z + vs%c(i)*min(zd, 0.0_dp) >= 0.0_dp
      else
         left = vs%p(i) + vs%k(i)*z + vs%c(i)*zd < 0.0_dp
      end if
   end function state_left

   !> The time within a piece of length left (a_z from a0 to a1 over it, from (z0, zd0)) at
   !> which support i changes state: lifts off when in contact (fly false), lands when in
   !> flight; by bisection to round-off, the state changed at the end of the piece.
   pure real(dp) function state_change(vs, i, fly, z0, zd0, a0, a1, left) result(hi)
      type(vertical_support), intent(in) :: vs
      integer, intent(in) :: i
      logical, intent(in) :: fly                    !! in flight at the piece's start
      real(dp), intent(in) :: z0, zd0, a0, a1, left
      real(dp) :: lo, mid, z, zd, mp(8)
      integer :: q

      lo = 0.0_dp
      hi = left
      do q = 1, bisections
         mid = 0.5_dp*(lo + hi)
         if (.not. (mid > lo .and. mid < hi)) exit
         if (fly) then
            call flight_at(z0, zd0, a0, a1, left, mid, z, zd)
         else
            call part_map(vs%wn(i), vs%c(i)/vs%m(i), mid, mp)
            call contact_at(mp, z0, zd0, a0, a0 + (a1 - a0)*mid/left, z, zd)
         end if
         if (state_left(vs, i, fly, z, zd)) then
            hi = mid
         else
            lo = mid
         end if
      end do
   end function state_change

   !> The contact map's end state from (z0, zd0) under a_z from a0 to a1.
   pure subroutine contact_at(mp, z0, zd0, a0, a1, z, zd)
      real(dp), intent(in) :: mp(8), z0, zd0, a0, a1
      real(dp), intent(out) :: z, zd

      z = mp(1)*z0 + mp(3)*zd0 + mp(5)*a0 + mp(7)*a1
      zd = mp(2)*z0 + mp(4)*zd0 + mp(6)*a0 + mp(8)*a1
   end subroutine contact_at

   !> The free fall from (z0, zd0) after s of a piece of length len over which a_z goes linearly
   !> from a0 to a1: z'' = a_z + g.
   pure subroutine flight_at(z0, zd0, a0, a1, len, s, z, zd)
      real(dp), intent(in) :: z0, zd0, a0, a1, len, s
      real(dp), intent(out) :: z, zd

      z = z0 + zd0*s + (g + a0)*s**2/2.0_dp + (a1 - a0)*s**3/(6.0_dp*len)
      zd = zd0 + (g + a0)*s + (a1 - a0)*s**2/(2.0_dp*len)
   end subroutine flight_at

   !> The peak uplift -(z + ds) of a flight over [0, tau] of a piece of length len (a_z from a0 to
   !> a1 over len): at the turning points z' = 0 within it, into gap.
   pure subroutine flight_peak(ds, z0, zd0, a0, a1, len, tau, gap)
      real(dp), intent(in) :: ds, z0, zd0, a0, a1, len, tau
      real(dp), intent(inout) :: gap
      real(dp) :: qa, qb, disc, r(2), z, zd
      integer :: k

      ! z' = zd0 + qb s + qa s^2
      qa = (a1 - a0)/(2.0_dp*len)
      qb = g + a0
      r = -1.0_dp
      if (qa == 0.0_dp) then
         if (qb /= 0.0_dp) r(1) = -zd0/qb
      else
         disc = qb*qb - 4.0_dp*qa*zd0
         if (disc >= 0.0_dp) then
            r(1) = (-qb - sqrt(disc))/(2.0_dp*qa)
            r(2) = (-qb + sqrt(disc))/(2.0_dp*qa)
         end if
      end if
      do k = 1, 2
         if (.not. (r(k) > 0.0_dp .and. r(k) < tau)) cycle
         call flight_at(z0, zd0, a0, a1, len, r(k), z, zd)
         gap = max(gap, -(z + ds))
      end do
   end subroutine flight_peak

   !> Support i's kinetic and potential energy at (z, zd) [J].
   pure subroutine energy_of(vs, i, z, zd, ek, ep)
      type(vertical_support), intent(in) :: vs
      integer, intent(in) :: i
      real(dp), intent(in) :: z, zd
      real(dp), intent(out) :: ek, ep
      real(dp) :: ds

      ek = 0.5_dp*vs%m(i)*zd*zd
      ds = vs%p(i)/vs%k(i)
      if (z >= -ds) then
         ep = 0.5_dp*vs%k(i)*z*z
      else
         ep = -vs%p(i)*z - 0.5_dp*vs%p(i)*ds
      end if
   end subroutine energy_of

end module fd_vertical_support
