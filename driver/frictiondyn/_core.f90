!> The f2py layer of frictiondyn: thin, flat entry points over the Fortran library, with
!> iso_c_binding kinds, explicit-shape arrays, a status and a message. No numerics here.
!> Errors never stop the process: they come back as status /= 0 and a message, which the
!> Python side (frictiondyn/_api.py) turns into an exception.
!>
!> status: 0 success, 1 bad deck or input, 2 solver failure, 3 buffer too small

!> Read and validate a deck (from the file `path`, or from `text` when from_text /= 0) and
!> return the size of its history and of its buffers.
subroutine fd_shape(path, text, from_text, ncol, nout, lhead, outdir, outname, history, status, message)
   use, intrinsic :: iso_c_binding, only: c_int, c_char
   use frictiondyn, only: error_type, run_config, shape_of
   implicit none
   character(len=*), intent(in) :: path          !! deck file, or name of a text deck
   character(len=*), intent(in) :: text          !! deck text (when from_text /= 0)
   integer(c_int), intent(in) :: from_text       !! 1: read text, 0: read the file
   integer(c_int), intent(out) :: ncol           !! columns of the history
   integer(c_int), intent(out) :: nout           !! samples of the history
   integer(c_int), intent(out) :: lhead          !! length of the header line
   character(kind=c_char, len=1), intent(out) :: outdir(1024)  !! &output dir
   character(kind=c_char, len=1), intent(out) :: outname(1024) !! &output name
   integer(c_int), intent(out) :: history        !! 1: &output write_history
   integer(c_int), intent(out) :: status         !! 0 or an error code
   character(kind=c_char, len=1), intent(out) :: message(4096) !! error message
   !f2py threadsafe
   type(run_config) :: cfg
   type(error_type), allocatable :: error
   integer :: nc, no

   ncol = 0; nout = 0; lhead = 0; history = 0
   outdir = ' '; outname = ' '
   call read_any(path, text, from_text, cfg, error)
   if (allocated(error)) then
      call fail(1, error%message, status, message)
      return
   end if
   call shape_of(cfg, nc, no)
   ncol = int(nc, c_int); nout = int(no, c_int)
   lhead = int(32*nc, c_int)
   call put(cfg%out%dir, outdir, status)
   if (status == 0) call put(cfg%out%name, outname, status)
   if (status /= 0) then
      call fail(3, 'output directory or name longer than 1024 characters', status, message)
      return
   end if
   history = merge(1_c_int, 0_c_int, cfg%out%history)
   call fail(0, '', status, message)
contains
   include 'fd_core_common.inc'
end subroutine fd_shape

!> Run a deck and return its history, header and JSON summary; writes no file.
subroutine fd_run(path, text, from_text, ncol, nout, lhead, lsum, hist, header, summary, status, message)
   use, intrinsic :: iso_c_binding, only: c_int, c_char, c_double
   use frictiondyn, only: error_type, run_config, result_type, run_config_solve, shape_of, &
                          summary_json, history_header
   implicit none
   character(len=*), intent(in) :: path          !! deck file, or name of a text deck
   character(len=*), intent(in) :: text          !! deck text (when from_text /= 0)
   integer(c_int), intent(in) :: from_text       !! 1: read text, 0: read the file
   integer(c_int), intent(in) :: ncol            !! columns, from fd_shape
   integer(c_int), intent(in) :: nout            !! samples, from fd_shape
   integer(c_int), intent(in) :: lhead           !! length of the header buffer
   integer(c_int), intent(in) :: lsum            !! length of the summary buffer
   real(c_double), intent(out) :: hist(ncol, nout)               !! history
   character(kind=c_char, len=1), intent(out) :: header(lhead)   !! 'name[unit],...'
   character(kind=c_char, len=1), intent(out) :: summary(lsum)   !! summary, JSON
   integer(c_int), intent(out) :: status         !! 0 or an error code
   character(kind=c_char, len=1), intent(out) :: message(4096) !! error message
   !f2py threadsafe
   type(run_config) :: cfg
   type(result_type) :: res
   type(error_type), allocatable :: error
   character(len=:), allocatable :: text_out
   integer :: nc, no

   hist = 0.0_c_double
   header = ' '
   summary = ' '
   call read_any(path, text, from_text, cfg, error)
   if (allocated(error)) then
      call fail(1, error%message, status, message)
      return
   end if
   call shape_of(cfg, nc, no)
   if (nc /= ncol .or. no /= nout) then
      call fail(3, 'history buffer of the wrong shape', status, message)
      return
   end if
   call run_config_solve(cfg, res, error)
   if (allocated(error)) then
      call fail(2, error%message, status, message)
      return
   end if
   hist = real(res%hist, c_double)
   call history_header(res, text_out)
   call put(text_out, header, status)
   if (status == 0) then
      call summary_json(cfg%model, res, cfg%deck_path, text_out, cfg%record)
      call put(text_out, summary, status)
   end if
   if (status /= 0) then
      call fail(3, 'header or summary buffer too small', status, message)
      return
   end if
   call fail(0, '', status, message)
contains
   include 'fd_core_common.inc'
end subroutine fd_run
