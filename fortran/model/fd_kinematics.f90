!> Kinematics of the friction devices, for every technique: device d between node_i and
!> node_j has the direction b_d = e_i - e_j (node 0, the table, dropped), its relative
!> displacement is s_d = b_d' u = u(node_i) - u(node_j), and its force F_d enters the
!> equations of motion as b_d F_d.
module fd_kinematics
   use fd_kinds, only: dp
   use fd_model, only: model_type
   implicit none
   private

   public :: device_kinematics, device_relative, add_device

contains

   !> Relative displacement and velocity of every device.
   pure subroutine device_kinematics(model, u, v, s, sd)
      type(model_type), intent(in) :: model   !! the model
      real(dp), intent(in) :: u(:)            !! displacements of the DOFs [m]
      real(dp), intent(in) :: v(:)            !! velocities of the DOFs [m/s]
      real(dp), intent(out) :: s(:)           !! relative displacement of each device [m]
      real(dp), intent(out) :: sd(:)          !! relative velocity of each device [m/s]
      integer :: d, i, j

      do d = 1, model%n_devices
         i = model%dev(d)%node_i; j = model%dev(d)%node_j
         s(d) = u(i); sd(d) = v(i)
         if (j > 0) then
            s(d) = s(d) - u(j); sd(d) = sd(d) - v(j)
         end if
      end do
   end subroutine device_kinematics

   !> b_d' y: the relative value across device d of a vector over the DOFs.
   pure real(dp) function device_relative(model, d, y) result(rel)
      type(model_type), intent(in) :: model   !! the model
      integer, intent(in) :: d                !! device
      real(dp), intent(in) :: y(:)            !! displacements, velocities, ... of the DOFs

      rel = y(model%dev(d)%node_i)
      if (model%dev(d)%node_j > 0) rel = rel - y(model%dev(d)%node_j)
   end function device_relative

   !> y = y + alpha b_d.
   pure subroutine add_device(model, d, alpha, y)
      type(model_type), intent(in) :: model   !! the model
      integer, intent(in) :: d                !! device
      real(dp), intent(in) :: alpha           !! factor of b_d
      real(dp), intent(inout) :: y(:)         !! vector over the DOFs

      y(model%dev(d)%node_i) = y(model%dev(d)%node_i) + alpha
      if (model%dev(d)%node_j > 0) y(model%dev(d)%node_j) = y(model%dev(d)%node_j) - alpha
   end subroutine add_device

end module fd_kinematics
