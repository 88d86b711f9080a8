!> The Fortran interfaces of fd_fileops.c and of the C library's calls on files the outputs
!> use: POSIX file creation, writes, close, rename, unlink, mkdir, rmdir, isatty, the output
!> lock, errno texts and the process id (gfortran's own I/O loses a full disk silently and
!> will not open one file on two units; docs/batch.md). Reading decks and records goes
!> through fd_textio. The file calls return 0 or an errno; os_error turns one into an error
!> naming what failed.
module fd_fileops
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_long, c_null_char
   use fd_error, only: error_type, fatal_error, stat_output
   implicit none
   private

   public :: c_lock_acquire, c_lock_release, c_unlink, c_rename, c_errno_text, c_getpid
   public :: c_file_create, c_file_write, c_file_close, os_error, c_mkdir, c_rmdir
   public :: path_call, c_isatty

   !> c_lock_acquire: the lock's path is a symbolic link or not a regular file (never followed).
   integer(c_int), parameter, public :: lock_not_file = -1

   !> A C function of a NUL-terminated path returning an int (mkdir, unlink: 0 or an errno;
   !> rmdir: 0 or -1; fd_tempfiles' removal of stale files: a count).
   abstract interface
      function path_call(path) bind(c) result(err)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int) :: err
      end function path_call
   end interface

   !> Create a directory (mode 0755 less the umask): 0 or errno.
   procedure(path_call), bind(c, name='fd_mkdir') :: c_mkdir
   !> Remove a file.
   procedure(path_call), bind(c, name='fd_unlink') :: c_unlink
   !> Remove an empty directory (the C library's rmdir: 0, or -1).
   procedure(path_call), bind(c, name='rmdir') :: c_rmdir

   interface
      !> Whether a file descriptor is a terminal: 1, else 0 (the C library's isatty).
      function c_isatty(fd) bind(c, name='isatty') result(yes)
         import :: c_int
         integer(c_int), value :: fd
         integer(c_int) :: yes
      end function c_isatty
      !> Take the lock file `path` (created, held while fd is open).
      function c_lock_acquire(path, fd) bind(c, name='fd_lock_acquire') result(err)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int), intent(out) :: fd
         integer(c_int) :: err
      end function c_lock_acquire
      !> Release and remove the lock file.
      function c_lock_release(path, fd) bind(c, name='fd_lock_release') result(err)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int), value :: fd
         integer(c_int) :: err
      end function c_lock_release
      !> Rename a file (atomic within a file system).
      function c_rename(old, new) bind(c, name='fd_rename') result(err)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: old(*), new(*)
         integer(c_int) :: err
      end function c_rename
      !> The text of an errno, NUL-terminated in buf.
      subroutine c_errno_text(err, buf, length) bind(c, name='fd_errno_text')
         import :: c_char, c_int
         integer(c_int), value :: err
         character(kind=c_char), intent(out) :: buf(*)
         integer(c_int), value :: length
      end subroutine c_errno_text
      !> The process id.
      function c_getpid() bind(c, name='fd_getpid') result(pid)
         import :: c_int
         integer(c_int) :: pid
      end function c_getpid
      !> Create a file exclusively (an existing one is an error).
      function c_file_create(path, fd) bind(c, name='fd_file_create') result(err)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int), intent(out) :: fd
         integer(c_int) :: err
      end function c_file_create
      !> Write all of buf (retrying short writes).
      function c_file_write(fd, buf, length) bind(c, name='fd_file_write') result(err)
         import :: c_char, c_int, c_long
         integer(c_int), value :: fd
         character(kind=c_char), intent(in) :: buf(*)
         integer(c_long), value :: length
         integer(c_int) :: err
      end function c_file_write
      !> Flush to disk (fsync) and close.
      function c_file_close(fd) bind(c, name='fd_file_close') result(err)
         import :: c_int
         integer(c_int), value :: fd
         integer(c_int) :: err
      end function c_file_close
   end interface

contains

   !> An error naming what failed and the system's reason (errno text), of stat_output.
   subroutine os_error(error, what, err)
      type(error_type), allocatable, intent(out) :: error !! the error
      character(len=*), intent(in) :: what                !! what failed
      integer(c_int), intent(in) :: err                   !! its errno
      character(kind=c_char, len=256) :: buf
      call c_errno_text(err, buf, int(len(buf), c_int))
      call fatal_error(error, what//": "//buf(1:max(0, index(buf, c_null_char) - 1)), stat_output)
   end subroutine os_error
end module fd_fileops
