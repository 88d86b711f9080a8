!> Temporary output names and the removal of stale ones (the Fortran side of
!> fd_tempfiles.c). A writer names its temporary files `.<file>.<tag>.tmp` beside their final
!> name with the tag of temp_tag, `<pid>_<host>_<salt>`; remove_stale_temps removes those of a
!> file whose process is gone on this machine (a run killed by SIGKILL leaves them), and never
!> one of a live process or of another machine.
module fd_tempfiles
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_long_long, c_null_char
   use fd_fileops, only: path_call
   implicit none
   private

   public :: temp_tag, remove_stale_temps

   interface
      subroutine c_temp_tag(buf, len, salt) bind(c, name='fd_temp_tag')
         import :: c_char, c_int, c_long_long
         character(kind=c_char), intent(out) :: buf(*)
         integer(c_int), value :: len
         integer(c_long_long), value :: salt
      end subroutine c_temp_tag
   end interface

   !> Remove the stale temporaries of a path: how many.
   procedure(path_call), bind(c, name='fd_remove_stale_temps') :: c_remove_stale_temps

contains

   !> The tag of this process's temporary names: `<pid>_<host>_<salt, hex>`.
   subroutine temp_tag(salt, tag)
      integer(c_long_long), intent(in) :: salt            !! tells the writers of one process apart
      character(len=:), allocatable, intent(out) :: tag   !! e.g. '12345_node07_3f9a0c1d'
      character(kind=c_char, len=320) :: buf
      call c_temp_tag(buf, int(len(buf), c_int), salt)
      tag = buf(1:index(buf, c_null_char) - 1)
   end subroutine temp_tag

   !> Remove the stale temporaries of the output file `path` (see the module); `removed`, when
   !> given, is how many.
   subroutine remove_stale_temps(path, removed)
      character(len=*), intent(in) :: path       !! the final name of an output file
      integer, intent(out), optional :: removed  !! temporaries removed
      integer(c_int) :: n
      n = c_remove_stale_temps(path//c_null_char)
      if (present(removed)) removed = int(n)
   end subroutine remove_stale_temps

end module fd_tempfiles
