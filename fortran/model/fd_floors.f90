!> Rigid floors: a building whose floor f moves as a rigid diaphragm with three DOFs at its
!> centre of mass (x_f, y_f): ux at DOF 3f - 2, uy at 3f - 1 and the rotation rz
!> (counter-clockwise, rad) at 3f. A plan point P of floor f moves by
!> (ux - rz (y_P - y_f), uy + rz (x_P - x_f)). An element of storey s (between floor s and
!> floor s - 1, floor 0 the ground) along the plan direction (cos a, sin a) through P deforms
!> by the difference of that motion along its direction above and below: s = b' u, with b
!> of at most six terms (plan_direction). Frames are springs k b b' (fd_stiffness' K_x);
!> braces with friction dampers are devices of direction b (fd_kinematics).
module fd_floors
   use fd_kinds, only: dp
   implicit none
   private

   public :: floor_dof, plan_direction, floor_inertia, max_plan_terms

   integer, parameter :: max_plan_terms = 6   !! terms of a plan element's direction

   real(dp), parameter :: pi = acos(-1.0_dp)

contains

   !> The DOF of component c (1 ux, 2 uy, 3 rz) of floor f.
   elemental integer function floor_dof(f, c) result(i)
      integer, intent(in) :: f   !! floor (1..n_floors)
      integer, intent(in) :: c   !! 1 ux, 2 uy, 3 rz

      i = 3*(f - 1) + c
   end function floor_dof

   !> The rotational inertia of a uniform rectangular floor of mass m and plan lx by ly about
   !> its centre: m (lx^2 + ly^2) / 12.
   elemental real(dp) function floor_inertia(m, lx, ly) result(j)
      real(dp), intent(in) :: m      !! mass [kg]
      real(dp), intent(in) :: lx, ly !! plan dimensions [m]

      j = m*(lx*lx + ly*ly)/12.0_dp
   end function floor_inertia

   !> The direction b of a plan element of storey s along angle `angle` (degrees from x,
   !> counter-clockwise) through the plan point (x, y): its terms (dof, coef)(1:nt), those of
   !> floor s first (ux, uy, rz) and then those of floor s - 1 (none for the ground); terms
   !> whose coefficient is 0 (cos 90 deg, an element through the centre of mass) left out.
   pure subroutine plan_direction(s, angle, x, y, cm_x, cm_y, dof, coef, nt)
      integer, intent(in) :: s                      !! storey (1..n_floors)
      real(dp), intent(in) :: angle                 !! direction [deg]
      real(dp), intent(in) :: x, y                  !! a point of the element's line [m]
      real(dp), intent(in) :: cm_x(:), cm_y(:)      !! the floors' centres of mass [m]
      integer, intent(out) :: dof(max_plan_terms)   !! DOFs of the terms
      real(dp), intent(out) :: coef(max_plan_terms) !! their coefficients [-, -, m]
      integer, intent(out) :: nt                    !! terms
      real(dp) :: c, sn, sgn, v(3)
      integer :: k, f, m

      c = cos(angle*pi/180.0_dp)
      sn = sin(angle*pi/180.0_dp)
      ! exact for the axes: an element along x or y has no term of the other translation
      if (modulo(angle, 90.0_dp) == 0.0_dp) then
         c = real(nint(c), dp)
         sn = real(nint(sn), dp)
      end if
      nt = 0
      dof = 0
      coef = 0.0_dp
      do k = 1, 2
         f = s + 1 - k
         if (f < 1) exit
         sgn = merge(1.0_dp, -1.0_dp, k == 1)
         ! the rotation's motion along (c, sn) at P: -c (y - y_f) + sn (x - x_f)
         v = [sgn*c, sgn*sn, sgn*(sn*(x - cm_x(f)) - c*(y - cm_y(f)))]
         do m = 1, 3
            if (v(m) == 0.0_dp) cycle
            nt = nt + 1
            dof(nt) = floor_dof(f, m)
            coef(nt) = v(m)
         end do
      end do
   end subroutine plan_direction

end module fd_floors
