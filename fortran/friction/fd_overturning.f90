!> The overturning of a building of rigid floors on planar bearings (&bearings overturning =
!> .true.; docs/theory.md 5.7). The floors a storey of bearings carries (floor s and above, for
!> bearings in storey s) form one rigid body on the bearings' vertical supports; the bearings
!> stand at the level of floor s - 1 (the bearing plane), floor f at the height
!> h_f = height(s) + ... + height(f) above it (the storey heights of &floors: floor s, the base
!> mat, at height(s), 0 when it lies in the plane). The inertia forces m_f a_f (a_f the floor's
!> absolute horizontal acceleration at its centre of mass) at those heights have the moments
!> O = (sum m_f h_f a_fx, sum m_f h_f a_fy), and the rigid mat shares them among equal supports
!> linearly in plan: dN_b = beta x'_b + gamma y'_b with (x', y') about the bearings' centroid
!> (so sum dN = 0), and the moment balance sum r'_b dN_b = -O gives
!>   dN_b = -r'_b' S^-1 O,   S = sum r'_b r'_b'  (the general 2x2 form),
!> principal axes (S diagonal) giving dN_b = -(O_x x'_b / sum x'^2 + O_y y'_b / sum y'^2). A
!> storey's bearings all on one line (S singular) cannot share a moment about that line.
!>
!> What a technique calls: overturning_forces for dN of every bearing from the accelerations of
!> one state (relative a of the DOFs, and the table's ag, ag2), then fd_friction_planar's
!> normal_force(dev, az, dn) or with_normal_force(dev0, az, dev, dn) per bearing component.
module fd_overturning
   use fd_kinds, only: dp
   use fd_model, only: model_type
   use fd_floors, only: floor_dof
   use fd_stiffness, only: influence_of
   implicit none
   private

   public :: overturning_arms, overturning_forces

contains

   !> Each bearing's arm S^-1 (x_b - x_c, y_b - y_c) over the bearings of its storey (the
   !> centroid (x_c, y_c) and S = sum r' r' of that storey's bearings). bad: the first storey
   !> whose bearings lie on one line (or are one), det S <= 1e-12 (trace S)^2; 0 when none.
   pure subroutine overturning_arms(storey, x, y, arm, bad)
      integer, intent(in) :: storey(:)      !! each bearing's storey
      real(dp), intent(in) :: x(:), y(:)    !! its plan point [m]
      real(dp), intent(out) :: arm(:, :)    !! (2, n) its arm [1/m]
      integer, intent(out) :: bad           !! a storey whose S is singular (0: none)
      real(dp) :: xc, yc, sxx, sxy, syy, det, dx, dy
      integer :: b, j, m

      bad = 0
      arm = 0.0_dp
      do b = 1, size(storey)
         ! each storey once, at its first bearing
         if (any(storey(1:b - 1) == storey(b))) cycle
         m = count(storey == storey(b))
         xc = sum(x, mask=storey == storey(b))/m
         yc = sum(y, mask=storey == storey(b))/m
         sxx = 0.0_dp; sxy = 0.0_dp; syy = 0.0_dp
         do j = b, size(storey)
            if (storey(j) /= storey(b)) cycle
            dx = x(j) - xc
            dy = y(j) - yc
            sxx = sxx + dx*dx; sxy = sxy + dx*dy; syy = syy + dy*dy
         end do
         det = sxx*syy - sxy*sxy
         if (.not. det > 1.0e-12_dp*(sxx + syy)**2) then
            if (bad == 0) bad = storey(b)
            cycle
         end if
         do j = b, size(storey)
            if (storey(j) /= storey(b)) cycle
            dx = x(j) - xc
            dy = y(j) - yc
            arm(1, j) = (syy*dx - sxy*dy)/det
            arm(2, j) = (sxx*dy - sxy*dx)/det
         end do
      end do
   end subroutine overturning_arms

   !> Each bearing's change of normal force dN_b = -arm_b . O from the overturning moments O
   !> of the floors its storey carries, at one state: a the DOFs' relative accelerations, ag
   !> and ag2 the table's (a_f = a + r ag + r2 ag2 at the floor's ux, uy). No allocation.
   pure subroutine overturning_forces(model, a, ag, ag2, dn)
      type(model_type), intent(in) :: model !! a building of rigid floors, overturning set
      real(dp), intent(in) :: a(:)          !! relative accelerations of the DOFs [m/s2]
      real(dp), intent(in) :: ag            !! the table's acceleration [m/s2]
      real(dp), intent(in) :: ag2           !! a second component's (0: none) [m/s2]
      real(dp), intent(out) :: dn(:)        !! (n_bearings) dN of each bearing [N]
      real(dp) :: ox, oy, h, ax, ay
      integer :: b, f, s, last, ix, iy

      last = 0
      ox = 0.0_dp; oy = 0.0_dp
      do b = 1, size(model%ot_storey)
         s = model%ot_storey(b)
         if (s /= last) then
            ox = 0.0_dp; oy = 0.0_dp; h = 0.0_dp
            do f = s, model%n_floors
               h = h + model%floor_height(f)
               ix = floor_dof(f, 1)
               iy = floor_dof(f, 2)
               ax = a(ix) + influence_of(model, ix)*ag
               ay = a(iy) + influence_of(model, iy)*ag
               if (allocated(model%influence2)) then
                  ax = ax + model%influence2(ix)*ag2
                  ay = ay + model%influence2(iy)*ag2
               end if
               ox = ox + model%mass(ix)*h*ax
               oy = oy + model%mass(iy)*h*ay
            end do
            last = s
         end if
         dn(b) = -(model%ot_arm(1, b)*ox + model%ot_arm(2, b)*oy)
      end do
   end subroutine overturning_forces

end module fd_overturning
