!> Exact (set-valued) Coulomb friction: while a device sticks its force is whatever keeps it
!> stuck, up to P mu; while it slides, P mu against the relative velocity. No state of its own
!> and no force law of the device's state: the techniques that integrate it (event_driven,
!> moreau_jean) find the sticking forces with the whole structure, event by event or impulse
!> by impulse. What the law says of itself is here.
module fd_friction_coulomb
   use fd_kinds, only: dp
   use fd_model, only: device_type
   use fd_device_state, only: law_traits_type, stuck_rigid
   implicit none
   private

   public :: coulomb_traits, coulomb_holds

contains

   !> What the Coulomb law says of itself: while it sticks, a rigid link; no band, no
   !> correctness condition, nothing that rings or alternates, no stored energy.
   pure function coulomb_traits() result(traits)
      type(law_traits_type) :: traits   !! the Coulomb law's traits

      traits = law_traits_type(stuck=stuck_rigid)
   end function coulomb_traits

   !> Whether a sticking device holds its nodes together (rigidly): P mu > 0.
   elemental logical function coulomb_holds(dev) result(holds)
      type(device_type), intent(in) :: dev     !! device parameters

      holds = dev%p*dev%mu > 0.0_dp
   end function coulomb_holds

end module fd_friction_coulomb
