!> The stiffness that is no spring between two nodes, K_x (the frames of rigid floors, whose
!> deformation mixes a floor's translations and its rotation), and the table motion's
!> direction over the DOFs, r (the influence vector: the load is -M r a_g). The model keeps
!> K_x by its entries on and above the diagonal (n_kx, kx_i, kx_j, kx_v) and r in
!> `influence`; this module is the one that reads them. The structure's stiffness is
!> K = sum_s k_s (e_i - e_j)(e_i - e_j)' over the springs + K_x.
module fd_stiffness
   use fd_kinds, only: dp
   use fd_model, only: model_type
   implicit none
   private

   public :: general_form, add_general_dense
   public :: influence_of, add_general_entry, stiffness_times, stiffness_form

contains

   !> ku = ku + K_x u.
   pure subroutine add_general_times(model, u, ku)
      type(model_type), intent(in) :: model  !! the model
      real(dp), intent(in) :: u(:)           !! a vector over the DOFs
      real(dp), intent(inout) :: ku(:)       !! the vector added to
      integer :: e, i, j

      do e = 1, model%n_kx
         i = model%kx_i(e); j = model%kx_j(e)
         ku(i) = ku(i) + model%kx_v(e)*u(j)
         if (i /= j) ku(j) = ku(j) + model%kx_v(e)*u(i)
      end do
   end subroutine add_general_times

   !> ku = K u, the structure's stiffness: the springs' and K_x's.
   pure subroutine stiffness_times(model, u, ku)
      type(model_type), intent(in) :: model  !! the model
      real(dp), intent(in) :: u(:)           !! a vector over the DOFs
      real(dp), intent(out) :: ku(:)         !! K u
      real(dp) :: x
      integer :: s

      ku = 0.0_dp
      do s = 1, model%n_springs
         x = model%spring_k(s)*stretch(model, s, u)
         if (model%spring_i(s) > 0) ku(model%spring_i(s)) = ku(model%spring_i(s)) + x
         if (model%spring_j(s) > 0) ku(model%spring_j(s)) = ku(model%spring_j(s)) - x
      end do
      call add_general_times(model, u, ku)
   end subroutine stiffness_times

   !> x' K y, the structure's stiffness: the springs' sum_s k_s (x_i - x_j)(y_i - y_j) (no
   !> cancellation), then K_x's.
   pure real(dp) function stiffness_form(model, x, y) result(e)
      type(model_type), intent(in) :: model  !! the model
      real(dp), intent(in) :: x(:), y(:)     !! vectors over the DOFs
      integer :: s

      e = 0.0_dp
      do s = 1, model%n_springs
         e = e + model%spring_k(s)*stretch(model, s, x)*stretch(model, s, y)
      end do
      if (model%n_kx > 0) e = e + general_form(model, x, y)
   end function stiffness_form

   !> x_i - x_j of spring s (node 0, the table, at rest).
   pure real(dp) function stretch(model, s, x) result(d)
      type(model_type), intent(in) :: model  !! the model
      integer, intent(in) :: s               !! the spring
      real(dp), intent(in) :: x(:)           !! a vector over the DOFs

      d = 0.0_dp
      if (model%spring_i(s) > 0) d = x(model%spring_i(s))
      if (model%spring_j(s) > 0) d = d - x(model%spring_j(s))
   end function stretch

   !> x' K_x y.
   pure real(dp) function general_form(model, x, y) result(e)
      type(model_type), intent(in) :: model  !! the model
      real(dp), intent(in) :: x(:), y(:)     !! vectors over the DOFs
      integer :: k, i, j

      e = 0.0_dp
      do k = 1, model%n_kx
         i = model%kx_i(k); j = model%kx_j(k)
         if (i == j) then
            e = e + model%kx_v(k)*x(i)*y(i)
         else
            e = e + model%kx_v(k)*(x(i)*y(j) + x(j)*y(i))
         end if
      end do
   end function general_form

   !> a = a + K_x (a dense matrix over the DOFs).
   pure subroutine add_general_dense(model, a)
      type(model_type), intent(in) :: model  !! the model
      real(dp), intent(inout) :: a(:, :)     !! matrix over the DOFs
      integer :: e, i, j

      do e = 1, model%n_kx
         i = model%kx_i(e); j = model%kx_j(e)
         a(i, j) = a(i, j) + model%kx_v(e)
         if (i /= j) a(j, i) = a(j, i) + model%kx_v(e)
      end do
   end subroutine add_general_dense

   !> r_i, the table motion's component along DOF i (1 when the model gives none).
   pure real(dp) function influence_of(model, i) result(r)
      type(model_type), intent(in) :: model  !! the model
      integer, intent(in) :: i               !! the DOF

      r = 1.0_dp
      if (allocated(model%influence)) r = model%influence(i)
   end function influence_of

   !> Add k b b' to K_x for a direction b given by its terms (dof(t), coef(t)): its entries
   !> on and above the diagonal, merged with those already there. kx_* grow as needed.
   pure subroutine add_general_entry(model, dof, coef, k)
      type(model_type), intent(inout) :: model !! the model
      integer, intent(in) :: dof(:)            !! the direction's DOFs (distinct)
      real(dp), intent(in) :: coef(:)          !! its coefficients
      real(dp), intent(in) :: k                !! the stiffness along it
      integer :: a, b, i, j, e, found

      if (.not. allocated(model%kx_i)) then
         allocate (model%kx_i(0), model%kx_j(0), model%kx_v(0))
         model%n_kx = 0
      end if
      do a = 1, size(dof)
         do b = 1, size(dof)
            i = dof(a); j = dof(b)
            if (i > j) cycle
            found = 0
            do e = 1, model%n_kx
               if (model%kx_i(e) == i .and. model%kx_j(e) == j) then
                  found = e
                  exit
               end if
            end do
            if (found > 0) then
               model%kx_v(found) = model%kx_v(found) + k*coef(a)*coef(b)
            else
               model%kx_i = [model%kx_i(1:model%n_kx), i]
               model%kx_j = [model%kx_j(1:model%n_kx), j]
               model%kx_v = [model%kx_v(1:model%n_kx), k*coef(a)*coef(b)]
               model%n_kx = model%n_kx + 1
            end if
         end do
      end do
   end subroutine add_general_entry

end module fd_stiffness
