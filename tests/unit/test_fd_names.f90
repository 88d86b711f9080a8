!> Unit tests of the name tables (fd_names): lookups without case or blanks, the lists in
!> messages, and the id <-> name round trip of every law and technique.
module test_fd_names
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_names, only: laws, techniques, damping_types, excitation_types, record_kinds, keyword_type, &
                       keyword_id, keyword_name, keyword_choices, law_id, law_choices, law_name, technique_name, &
                       law_velocity, law_hysteretic, law_coulomb, damping_rayleigh, technique_event_driven
   use fd_textio, only: lower
   implicit none
   private

   public :: collect_names

contains

   subroutine collect_names(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("lookups", test_lookup), &
                  new_unittest("lists in messages", test_choices), &
                  new_unittest("tables well formed", test_tables) &
                  ]
   end subroutine collect_names

   subroutine test_lookup(error)
      type(error_type), allocatable, intent(out) :: error

      call check(error, law_id('Velocity ') == law_velocity .and. law_id('HYSTERETIC') == law_hysteretic .and. &
                 law_id('coulomb') == law_coulomb, "law names")
      if (allocated(error)) return
      call check(error, law_id('coloumb') == 0 .and. law_id('') == 0, "unknown law names")
      if (allocated(error)) return
      call check(error, keyword_id(damping_types, 'Rayleigh') == damping_rayleigh, "damping type")
      if (allocated(error)) return
      call check(error, keyword_id(techniques, 'event_driven') == technique_event_driven .and. &
                 keyword_id(techniques, 'event-driven') == 0, "technique names")
   end subroutine test_lookup

   subroutine test_choices(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text

      call keyword_choices(damping_types, text)
      call check(error, text, "'stiffness' (C = psi K, the paper), 'rayleigh' (C = a0 M + a1 K), 'none', "// &
                 "'modal' (xi per mode of the stuck system)")
      if (allocated(error)) return
      call keyword_choices(excitation_types, text)
      call check(error, text, "'harmonic', 'record', 'none'")
      if (allocated(error)) return
      call law_choices(text)
      call check(error, text, "'velocity', 'hysteretic', 'coulomb'")
      if (allocated(error)) return
      call law_choices(text, regularized=.true.)
      call check(error, text, "'velocity', 'hysteretic'")
      if (allocated(error)) return
      call law_choices(text, regularized=.false.)
      call check(error, text, "'coulomb'")
   end subroutine test_choices

   !> Every name lower case, unique in its table, and found again from its id.
   subroutine test_tables(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: i

      do i = 1, size(laws)
         call check(error, law_id(law_name(i)) == i .and. lower(laws(i)%name) == laws(i)%name, &
                    "law "//trim(laws(i)%name))
         if (allocated(error)) return
      end do
      do i = 1, size(techniques)
         call check(error, keyword_id(techniques, technique_name(i)) == i, "technique "//trim(techniques(i)%name))
         if (allocated(error)) return
      end do
      call check(error, trim(law_name(0)) == 'unknown' .and. trim(technique_name(size(techniques) + 1)) == 'unknown', &
                 "ids outside the tables")
      if (allocated(error)) return
      call unique(damping_types, "damping types")
      if (allocated(error)) return
      call unique(excitation_types, "excitation types")
      if (allocated(error)) return
      call unique(record_kinds, "record kinds")
      if (allocated(error)) return
      call unique(techniques, "techniques")
   contains
      subroutine unique(table, what)
         type(keyword_type), intent(in) :: table(:)
         character(len=*), intent(in) :: what
         integer :: j
         do j = 1, size(table)
            call check(error, keyword_id(table, table(j)%name) == j .and. lower(table(j)%name) == table(j)%name, &
                       what//": "//trim(table(j)%name))
            if (allocated(error)) return
            call check(error, keyword_id(table, keyword_name(table, j)) == j, what//": the name of id "// &
                       trim(table(j)%name))
            if (allocated(error)) return
         end do
         call check(error, keyword_name(table, 0) == 'unknown' .and. keyword_name(table, size(table) + 1) == 'unknown', &
                    what//": ids outside the table")
      end subroutine unique
   end subroutine test_tables

end module test_fd_names
