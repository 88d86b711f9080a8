!> Working precision of frictiondyn: one real kind everywhere.
module fd_kinds
   use, intrinsic :: iso_fortran_env, only: real64
   implicit none
   private

   public :: dp

   integer, parameter :: dp = real64 !! double precision, used for every real in the library

end module fd_kinds
