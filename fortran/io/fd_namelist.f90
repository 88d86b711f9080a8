!> Generic support for namelist decks: a deck held in memory as lines, checked to be well
!> formed (every character either in a group, in a comment or blank: scan_deck), the text
!> of one group found in it, and messages that name the file, group, line, variable and value.
!> The group readers in fd_deck do the namelist reads themselves (a namelist can only be
!> read where it is declared), in a loop with next_read: on failure the group is re-read
!> one assignment at a time (group_item) to find the variable and value at fault.
module fd_namelist
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_text, stat_no_memory, echo_chars
   use fd_textio, only: line_type, read_text_file, split_lines, lower
   use fd_sort, only: sort_keys, stable_order
   implicit none
   private

   public :: deck_text, group_text, load_deck, deck_from_string, find_group, group_item, group_read_error, next_read
   public :: check_groups, group_opened, scan_deck, group_span, longest_string, given_elements

   character(len=*), parameter :: blanks = ' '//achar(9)  !! what separates words on a line

   !> Where one group lies in a deck.
   type :: group_span
      character(len=64) :: name = ''   !! group name, lower case
      integer :: first_line = 0        !! deck line of '&name'
      integer :: first_col = 0         !! its column of '&' (or '$')
      integer :: name_end = 0          !! column of the name's last character
      integer :: last_line = 0         !! deck line of the end ('/', '&end' or '$end')
      integer :: last_col = 0          !! its column
      integer :: close_len = 1         !! its length: 1 for '/', 4 for '&end', '$end'
   end type group_span

   !> A whole deck in memory.
   type :: deck_text
      character(len=:), allocatable :: path          !! the deck file
      type(line_type), allocatable :: lines(:)       !! its lines
      !> its groups, once check_groups has found the deck well formed (find_group then
      !> looks them up instead of scanning the deck again for every group)
      type(group_span), allocatable :: spans(:)
   end type deck_text

   !> One group of a deck, ready for an internal namelist read.
   type :: group_text
      character(len=:), allocatable :: name          !! group name, lower case
      character(len=:), allocatable :: lines(:)      !! its lines, from '&name' to '/'
      integer :: first_line = 0                      !! deck line of '&name'
      type(line_type), allocatable :: items(:)       !! the assignments 'var = value'
      integer, allocatable :: item_line(:)           !! deck line of each assignment
      !> what lines holds (next_read): 0 the whole group; i > 0 its assignment i alone, re-read
      !> after the whole group failed to read
      integer :: item = 0
      character(len=:), allocatable :: whole_msg     !! the reader's message on the whole group
   end type group_text

   !> The variables of a group's assignments, which repeated_item sorts them by.
   type, extends(sort_keys) :: variable_keys
      character(len=64), allocatable :: bases(:)   !! each assignment's variable, without subscripts
   contains
      procedure :: before => variable_before
   end type variable_keys

contains

   !> Read a deck file into memory.
   subroutine load_deck(path, deck, error)
      character(len=*), intent(in) :: path                !! deck file
      type(deck_text), intent(out) :: deck                !! its text
      type(error_type), allocatable, intent(out) :: error !! missing or unreadable file

      deck%path = path
      call read_text_file(path, deck%lines, error)
      if (allocated(error)) then
         error%message = "deck: "//error%message
         return
      end if
      call drop_bom(deck)
   end subroutine load_deck

   !> A UTF-8 byte order mark before the first line (some Windows editors write one) is no
   !> text of the deck.
   pure subroutine drop_bom(deck)
      type(deck_text), intent(inout) :: deck
      character(len=*), parameter :: bom = achar(239)//achar(187)//achar(191)

      if (.not. allocated(deck%lines)) return
      if (size(deck%lines) == 0) return
      if (len(deck%lines(1)%s) < 3) return
      if (deck%lines(1)%s(1:3) == bom) deck%lines(1)%s = deck%lines(1)%s(4:)
   end subroutine drop_bom

   !> A deck given as text (lines separated by newlines); path names it in messages and
   !> is the base of relative record paths.
   pure subroutine deck_from_string(text, path, deck, error)
      character(len=*), intent(in) :: text   !! the deck
      character(len=*), intent(in) :: path   !! name used for the deck
      type(deck_text), intent(out) :: deck   !! its text as lines
      type(error_type), allocatable, intent(out), optional :: error !! not enough memory
      integer :: stat

      deck%path = path
      call split_lines(text, deck%lines, stat)
      if (stat /= 0 .and. present(error)) call fatal_error(error, path//": not enough memory for the lines "// &
                                                           "of the deck ("//trim(fmt_int(len(text)))//" bytes)")
      if (stat == 0) call drop_bom(deck)
   end subroutine deck_from_string

   !> The group a line opens ('&name' or the legacy '$name' as its first word, after blanks
   !> or tabs), lower case; blank if none ('&end' closes, it does not open).
   pure function group_opened(line) result(name)
      character(len=*), intent(in) :: line !! a deck line
      character(len=64) :: name            !! the group it opens, lower case; blank if none
      integer :: e, b

      name = ''
      b = verify(line, blanks)
      if (b == 0) return
      if (line(b:b) /= '&' .and. line(b:b) /= '$') return
      e = b + 1
      do while (e <= len(line))
         if (.not. is_name_char(line(e:e))) exit
         e = e + 1
      end do
      if (e == b + 1) return
      name = lower(line(b + 1:e - 1))
      if (name == 'end') name = ''
   end function group_opened

   !> Every group of the deck must be one of the known names, and appear once; the deck
   !> must be well formed (see scan_deck).
   subroutine check_groups(deck, known, error)
      type(deck_text), intent(inout) :: deck              !! the deck (its groups kept: deck%spans)
      character(len=*), intent(in) :: known(:)            !! names of the known groups
      type(error_type), allocatable, intent(out) :: error !! unknown or repeated group, or bad text
      type(group_span), allocatable :: spans(:)
      integer :: i, j, count(size(known))

      if (allocated(deck%spans)) deallocate (deck%spans)
      call scan_deck(deck, spans, error)
      if (allocated(error)) return
      count = 0
      do i = 1, size(spans)
         do j = 1, size(known)
            if (spans(i)%name == trim(known(j))) exit
         end do
         if (j > size(known)) then
            call fatal_error(error, deck%path//", line "//trim(fmt_int(spans(i)%first_line))//": unknown group &"// &
                             trim(spans(i)%name)//"; the groups are "//trim(join(known)))
            return
         end if
         count(j) = count(j) + 1
         if (count(j) > 1) then
            call fatal_error(error, deck%path//", line "//trim(fmt_int(spans(i)%first_line))//": group &"// &
                             trim(spans(i)%name)//" appears more than once")
            return
         end if
      end do
      call move_alloc(spans, deck%spans)
   contains
      function join(words) result(str)
         character(len=*), intent(in) :: words(:)
         character(len=512) :: str
         integer :: k
         str = ''
         do k = 1, size(words)
            str = trim(str)//' &'//trim(words(k))
            if (k < size(words)) str = trim(str)//','
         end do
         str = adjustl(str)
      end function join
   end subroutine check_groups

   !> Where the groups of a deck lie. The deck must be well formed: a group opens with
   !> '&name' (or the legacy '$name') as the first word of its line and closes with '/'
   !> (or '&end', '$end') outside quotes and comments; outside groups only blank lines and
   !> comments ('!') are allowed; inside a group '&' and '$' appear only in quoted strings;
   !> no NUL character anywhere. Anything else is an error naming the deck and the line:
   !> nothing in a deck is skipped unread.
   pure subroutine scan_deck(deck, spans, error)
      type(deck_text), intent(in) :: deck                 !! the deck
      type(group_span), allocatable, intent(out) :: spans(:) !! its groups, in order
      type(error_type), allocatable, intent(out) :: error !! the first thing not well formed
      type(group_span), allocatable :: grown(:)
      type(group_span) :: cur
      integer :: i, k, b, e, n, nl
      logical :: inside
      character(len=1) :: quote, ch
      character(len=:), allocatable :: where

      allocate (spans(8))
      n = 0
      inside = .false.
      do i = 1, size(deck%lines)
         associate (line => deck%lines(i)%s)
            nl = len(line)
            if (index(line, achar(0)) > 0) then
               where = deck%path//", line "//trim(fmt_int(i))   ! formatted only for a message
               call fatal_error(error, where//": a NUL character (byte 0) in the deck: not a text file")
               return
            end if
            k = 1
            if (.not. inside) then
               b = verify(line, blanks)
               if (b == 0) cycle
               if (line(b:b) == '!') cycle
               if (line(b:b) /= '&' .and. line(b:b) /= '$') then
                  where = deck%path//", line "//trim(fmt_int(i))   ! formatted only for a message
                  call outside_text(where, line, b, error)
                  return
               end if
               e = b + 1
               do while (e <= nl)
                  if (.not. is_name_char(line(e:e))) exit
                  e = e + 1
               end do
               if (e == b + 1) then
                  where = deck%path//", line "//trim(fmt_int(i))   ! formatted only for a message
                  call fatal_error(error, where//": '"//trim(shown(line(b:)))//"': '"//line(b:b)// &
                                   "' must be followed by the group name, with no blank ('"//line(b:b)//"name')")
                  return
               end if
               if (lower(line(b + 1:e - 1)) == 'end') then
                  where = deck%path//", line "//trim(fmt_int(i))   ! formatted only for a message
                  call fatal_error(error, where//": '"//line(b:e - 1)//"' outside any group (a group closed twice?)")
                  return
               end if
               if (e <= nl) then
                  if (scan(line(e:e), blanks//',/!') == 0) then
                     where = deck%path//", line "//trim(fmt_int(i))   ! formatted only for a message
                     call fatal_error(error, where//": '"//trim(shown(line(b:)))//"' does not open a group: "// &
                                      "a group name is letters, digits and '_', followed by a blank")
                     return
                  end if
               end if
               cur = group_span()
               if (e - 1 - b > len(cur%name)) then   ! longer than any group's name
                  where = deck%path//", line "//trim(fmt_int(i))   ! formatted only for a message
                  call fatal_error(error, where//": unknown group "//line(b:b)//trim(shown(line(b + 1:e - 1))))
                  return
               end if
               cur%name = lower(line(b + 1:e - 1))
               cur%first_line = i
               cur%first_col = b
               cur%name_end = e - 1
               inside = .true.
               k = e
            else
               ! a line of an open group that opens another group: the open one is not closed
               if (len_trim(group_opened(line)) > 0) then
                  call fatal_error(error, deck%path//", group &"//trim(cur%name)//" (line "// &
                                   trim(fmt_int(cur%first_line))//"): not closed by '/' before line "// &
                                   trim(fmt_int(i))//" ('"//trim(shown(adjustl(line)))//"')")
                  return
               end if
            end if
            ! inside the group: look for its end
            quote = ' '
            do while (k <= nl)
               ch = line(k:k)
               if (quote /= ' ') then
                  if (ch == quote) quote = ' '
               else if (ch == '"' .or. ch == "'") then
                  quote = ch
               else if (ch == '!') then
                  exit
               else if (ch == '/') then
                  cur%last_line = i; cur%last_col = k; cur%close_len = 1
                  exit
               else if (ch == '&' .or. ch == '$') then
                  if (closes(line, k)) then
                     cur%last_line = i; cur%last_col = k; cur%close_len = 4
                     exit
                  end if
                  where = deck%path//", line "//trim(fmt_int(i))   ! formatted only for a message
                  call fatal_error(error, where//", group &"//trim(cur%name)//": '"//trim(shown(line(k:)))//"': '"//ch// &
                                   "' inside a group, outside quotes (a group ends with '/'; a group opens on a line "// &
                                   "of its own)")
                  return
               end if
               k = k + 1
            end do
            ! a text continued on the next line: the namelist reader gets the group's lines as
            ! records padded with blanks, which would go into the text (or end it there)
            if (quote /= ' ') then
               call fatal_error(error, deck%path//", line "//trim(fmt_int(i))//", group &"//trim(cur%name)// &
                                ": a text ("//quote//"...) is not closed on its line; close each text on the "// &
                                "line where it starts")
               return
            end if
            if (cur%last_line == i) then
               inside = .false.
               if (n == size(spans)) then
                  allocate (grown(2*n))
                  grown(1:n) = spans
                  call move_alloc(grown, spans)
               end if
               n = n + 1
               spans(n) = cur
               ! after the end of a group: nothing but a comment
               k = k + cur%close_len
               if (k <= nl) then
                  b = verify(line(k:), blanks)
                  if (b > 0) then
                     if (line(k + b - 1:k + b - 1) /= '!') then
                        where = deck%path//", line "//trim(fmt_int(i))   ! formatted only for a message
                        call fatal_error(error, where//": '"//trim(shown(line(k + b - 1:)))//"' after the end of group &"// &
                                         trim(cur%name)//": a group ends its line (only a comment may follow)")
                        return
                     end if
                  end if
               end if
            end if
         end associate
      end do
      if (inside) then
         call fatal_error(error, deck%path//", group &"//trim(cur%name)//" (line "//trim(fmt_int(cur%first_line))// &
                          "): not closed by '/'")
         return
      end if
      spans = spans(1:n)
   end subroutine scan_deck

   !> Whether '&end' or '$end' (any case) starts at k and ends there (no name character follows).
   pure logical function closes(line, k)
      character(len=*), intent(in) :: line
      integer, intent(in) :: k

      closes = .false.
      if (k + 3 > len(line)) return
      if (lower(line(k + 1:k + 3)) /= 'end') return
      closes = .true.
      if (k + 4 <= len(line)) closes = .not. is_name_char(line(k + 4:k + 4))
   end function closes

   !> The error for text outside any group, saying what it looks like.
   pure subroutine outside_text(where, line, b, error)
      character(len=*), intent(in) :: where, line
      integer, intent(in) :: b                            !! first non-blank character
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: what
      integer :: amp, i

      amp = scan(line, '&$')
      if (line(b:b) == '/') then
         what = "a '/' outside any group (a group closed twice?)"
      else if (amp > 0) then
         what = "'"//line(amp:amp)//"' not read as the start of a group: a group opens with '"//line(amp:amp)// &
                "name' as the first word of its line, with only blanks or tabs before it"
         do i = b, amp - 1
            if (iachar(line(i:i)) > 126) then
               what = what//" (here a non-ASCII character, byte "//trim(fmt_int(iachar(line(i:i))))//", comes before it)"
               exit
            end if
         end do
      else if (index(line, '=') > 0) then
         what = "an assignment outside any group"
      else
         what = "text outside any group"
      end if
      call fatal_error(error, where//": '"//trim(shown(line(b:)))//"': "//what// &
                       "; between groups only blank lines and comments ('!') are allowed")
   end subroutine outside_text

   !> Deck text as shown in a message (fd_error's fmt_text): at most 80 characters (cut on a
   !> UTF-8 character boundary, the length said), control characters shown as '?', trailing
   !> blanks dropped.
   pure function shown(text) result(out)
      character(len=*), intent(in) :: text
      character(len=4*echo_chars + 32) :: out
      out = fmt_text(text)
   end function shown

   pure logical function is_name_char(c)
      character(len=1), intent(in) :: c
      is_name_char = (c >= 'a' .and. c <= 'z') .or. (c >= 'A' .and. c <= 'Z') .or. &
                     (c >= '0' .and. c <= '9') .or. c == '_'
   end function is_name_char

   !> Find a group in the deck and split it into assignments.
   subroutine find_group(deck, name, grp, found, error)
      type(deck_text), intent(in) :: deck                 !! the deck
      character(len=*), intent(in) :: name                !! group name, lower case
      type(group_text), intent(out) :: grp                !! the group's text
      logical, intent(out) :: found                       !! the group is present
      type(error_type), allocatable, intent(out) :: error !! deck not well formed, or a variable
                                                          !! assigned twice
      type(group_span), allocatable :: spans(:)
      type(group_span) :: sp
      integer :: i, first, last, width, n, cap, c1, c2, j, stat
      character(len=:), allocatable :: body, line, var, first_var
      integer, allocatable :: line_of(:)

      grp%name = name
      found = .false.
      if (allocated(deck%spans)) then
         spans = deck%spans
      else
         call scan_deck(deck, spans, error)
         if (allocated(error)) return
      end if
      do i = 1, size(spans)
         if (spans(i)%name == name) exit
      end do
      if (i > size(spans)) return
      sp = spans(i)
      found = .true.
      first = sp%first_line
      last = sp%last_line
      grp%first_line = first
      ! the group's lines as the namelist reader gets them: '&name' (for '$name' too) up to
      ! its end, which becomes '/'
      width = 1
      do i = first, last
         width = max(width, len(deck%lines(i)%s) + 2)
      end do
      allocate (character(len=width) :: grp%lines(last - first + 1), stat=stat)
      if (stat /= 0) then
         call no_memory(); return
      end if
      cap = 0
      do i = first, last
         line = deck%lines(i)%s
         if (i == last) line = line(1:sp%last_col - 1)//' /'
         ! comments blanked: gfortran's reader takes a value separator followed by a comment
         ! and the end of the line for a null value ('u0 = 0.01, ! m' then '0.02' on the next
         ! line would give u0 = 0.01, (unchanged), 0.02)
         c1 = 1
         if (i == first) c1 = sp%name_end + 1
         c2 = comment_column(line, c1)
         if (c2 > 0) line(c2:) = ' '
         if (i == first) line(sp%first_col:sp%first_col) = '&'
         grp%lines(i - first + 1) = line
         cap = cap + len(line) + 1
      end do
      ! body: the text after '&name' up to the end, comments removed (n characters used)
      allocate (character(len=cap) :: body, stat=stat)
      if (stat == 0) allocate (line_of(cap), stat=stat)
      if (stat /= 0) then
         call no_memory(); return
      end if
      n = 0
      do i = first, last
         c1 = 1
         c2 = len_trim(grp%lines(i - first + 1))    ! its comment blanked above
         if (i == first) c1 = sp%name_end + 1
         if (i == last) c2 = sp%last_col - 1
         call append_line(grp%lines(i - first + 1)(1:max(c2, c1 - 1)), c1, body, line_of, n, i)
      end do
      call split_items(body(1:n), line_of(1:n), grp%items, grp%item_line, stat)
      if (stat /= 0) then
         call no_memory(); return
      end if
      ! a variable (or array element) given twice: the namelist reader would keep the last
      call repeated_item(grp%items, i, j, stat)
      if (stat /= 0) then
         call no_memory(); return
      end if
      if (i > 0) then
         call item_variable(grp%items(i)%s, var)
         call item_variable(grp%items(j)%s, first_var)
         if (var == first_var) then
            call fatal_error(error, deck%path//", group &"//name//", line "//trim(fmt_int(grp%item_line(i)))// &
                             ": '"//var//"' is assigned again (first at line "//trim(fmt_int(grp%item_line(j)))// &
                             "); give each variable once")
         else
            call fatal_error(error, deck%path//", group &"//name//", line "//trim(fmt_int(grp%item_line(i)))// &
                             ": '"//var//"' sets again what '"//first_var//"' set at line "// &
                             trim(fmt_int(grp%item_line(j)))//"; give each variable or element once")
         end if
      end if
   contains
      subroutine no_memory()
         call fatal_error(error, deck%path//", group &"//name//" (line "//trim(fmt_int(first))// &
                          "): not enough memory to read it", stat_no_memory)
      end subroutine no_memory
   end subroutine find_group

   !> The first assignment (i) that sets the same variable or element as an earlier one (j);
   !> i = 0 if none. Names are sorted (stable_order): linear-logarithmic in the assignments.
   pure subroutine repeated_item(items, i, j, stat)
      type(line_type), intent(in) :: items(:)   !! the assignments of a group
      integer, intent(out) :: i                  !! the repeated one, 0 if none
      integer, intent(out) :: j                  !! the earlier one it repeats
      integer, intent(out) :: stat               !! 0, or not enough memory
      integer, parameter :: pairwise_max = 2000  !! longest run of one variable compared pair by pair
      character(len=64), allocatable :: names(:)
      character(len=:), allocatable :: var
      type(variable_keys) :: keys
      integer, allocatable :: order(:)
      integer :: k, n, c, r0, r1, p, q, ip, iq

      i = 0; j = 0
      n = size(items)
      allocate (names(n), keys%bases(n), order(n), stat=stat)
      if (stat /= 0 .or. n < 2) return
      do k = 1, n
         call item_variable(items(k)%s, var)
         names(k) = var
         if (len(var) > len(names)) names(k) = ''   ! not a variable of any group: the reader rejects it
         c = index(names(k), '(')
         keys%bases(k) = names(k)
         if (c > 0) then
            keys%bases(k) = names(k)(1:c - 1)
         else if (len_trim(names(k)) > 0 .and. len_trim(names(k)) < len(names) - 12) then
            ! a whole array given m values sets its elements 1 to m ('mass = 1.0, 2.0' leaves
            ! mass(3) to a later 'mass(3) = ...'): written as that section
            names(k) = trim(names(k))//'(1:'//trim(fmt_int(max(1, value_count(items(k)%s))))//')'
         end if
         order(k) = k
      end do
      ! order by (variable, position): stable_order keeps the deck's order within a variable
      call stable_order(keys, order, stat)
      if (stat /= 0) return
      ! the assignments of one variable are adjacent, in deck order: two of them that set the
      ! same element ('mass = ...' and 'mass(2) = ...', 'mass(1:2)' and 'mass(02)') repeat it;
      ! report the repeat that comes first in the deck
      r0 = 1
      do while (r0 <= n)
         r1 = r0
         do while (r1 < n)
            if (keys%bases(order(r1 + 1)) /= keys%bases(order(r0))) exit
            r1 = r1 + 1
         end do
         if (r1 > r0 .and. len_trim(keys%bases(order(r0))) > 0) then
            do q = r0 + 1, r1
               ! each earlier one; in a very long run its neighbour only (deck order)
               do p = merge(q - 1, r0, r1 - r0 >= pairwise_max), q - 1
                  ip = order(p); iq = order(q)
                  if (.not. same_elements(trim(names(ip)), trim(names(iq)))) cycle
                  if (i == 0 .or. iq < i) then
                     i = iq; j = ip
                  end if
                  exit
               end do
            end do
         end if
         r0 = r1 + 1
      end do
   end subroutine repeated_item

   !> Whether assignment a's variable goes before b's (their names without subscripts, in
   !> ASCII order): repeated_item's sort.
   pure logical function variable_before(keys, a, b) result(before)
      class(variable_keys), intent(in) :: keys   !! the assignments' variables
      integer, intent(in) :: a, b                !! two assignments

      before = llt(keys%bases(a), keys%bases(b))
   end function variable_before

   !> Whether two assignments of one variable ('mass', 'mass(2)', 'mu_table_v(1:3,2)',
   !> 'label(1)(1:4)', lower case without blanks) set a common element. A whole variable
   !> overlaps any part of it; subscripts that are integers or triplets ('l:u:s', bounds
   !> omitted) are compared as sets, others as text; a substring belongs to its element.
   pure logical function same_elements(a, b)
      character(len=*), intent(in) :: a, b
      character(len=:), allocatable :: sa, sb
      integer :: ka, kb, ea, eb

      same_elements = .true.
      call subscript(a, sa)
      call subscript(b, sb)
      if (len(sa) == 0 .or. len(sb) == 0) return
      if (count_char(sa, ',') /= count_char(sb, ',')) then
         ! a whole array (its first elements, '(1:m)') and an element of a 2-D one: taken to
         ! overlap; otherwise a different rank, which the reader rejects
         same_elements = index(a, '(1:') == len(a) - len(sa) - 1 .or. index(b, '(1:') == len(b) - len(sb) - 1
         return
      end if
      ka = 1; kb = 1
      do
         ea = index(sa(ka:), ','); eb = index(sb(kb:), ',')
         if (ea == 0) then
            same_elements = dims_overlap(sa(ka:), sb(kb:))
            if (same_elements) then   ! the same element: two substrings of it may be apart
               call subscript(a(index(a, ')') + 1:), sa)
               call subscript(b(index(b, ')') + 1:), sb)
               if (len(sa) > 0 .and. len(sb) > 0) same_elements = dims_overlap(sa, sb)
            end if
            return
         end if
         if (.not. dims_overlap(sa(ka:ka + ea - 2), sb(kb:kb + eb - 2))) then
            same_elements = .false.
            return
         end if
         ka = ka + ea; kb = kb + eb
      end do
   contains
      !> The text between the first parentheses ('' for a whole variable).
      pure subroutine subscript(v, sub)
         character(len=*), intent(in) :: v
         character(len=:), allocatable, intent(out) :: sub
         integer :: o, cl
         sub = ''
         o = index(v, '(')
         if (o == 0) return
         cl = index(v(o:), ')')
         if (cl == 0) return
         sub = v(o + 1:o + cl - 2)
      end subroutine subscript
   end function same_elements

   !> Whether two subscripts of one dimension ('3', '1:4', '2:10:2', ':') share an index.
   pure logical function dims_overlap(da, db)
      character(len=*), intent(in) :: da, db
      integer, parameter :: big = 2**30 - 1   !! an omitted bound
      integer :: la, ua, sa, lb, ub, sb, k, x
      logical :: oka, okb

      call triplet(da, la, ua, sa, oka)
      call triplet(db, lb, ub, sb, okb)
      if (.not. (oka .and. okb)) then
         dims_overlap = da == db
         return
      end if
      dims_overlap = .false.
      if (ua < la .or. ub < lb) return                       ! an empty section
      if (max(la, lb) > min(ua, ub)) return                  ! disjoint ranges
      dims_overlap = .true.
      if (sa == 1 .or. sb == 1) return
      if ((ua - la)/sa > 100000 .and. (ub - lb)/sb > 100000) return   ! long strided sections: their ranges
      ! the shorter progression's indices, each tested against the other
      if ((ua - la)/sa <= (ub - lb)/sb) then
         do k = 0, (ua - la)/sa
            x = la + k*sa
            if (x >= lb .and. x <= ub .and. mod(x - lb, sb) == 0) return
         end do
      else
         do k = 0, (ub - lb)/sb
            x = lb + k*sb
            if (x >= la .and. x <= ua .and. mod(x - la, sa) == 0) return
         end do
      end if
      dims_overlap = .false.
   contains
      !> A subscript as the ascending progression lo, lo + st, ..., hi; ok = .false. when it is
      !> not integers (bounds omitted count as unbounded).
      pure subroutine triplet(d, lo, hi, st, ok)
         character(len=*), intent(in) :: d
         integer, intent(out) :: lo, hi, st
         logical, intent(out) :: ok
         integer :: f
         logical :: lo_given, hi_given
         lo = -big; hi = big; st = 1
         if (index(d, ':') == 0) then
            call int_of(d, lo, ok)
            hi = lo
            return
         end if
         call triplet_parts(d, lo, hi, st, lo_given, hi_given, ok)
         if (.not. ok) return
         if (st < 0) then   ! l:u:-s runs down from l to u: the same set as last..l, ascending
            if (.not. (lo_given .and. hi_given)) then
               ok = .false.   ! an omitted bound with a negative stride: compared as text
               return
            end if
            f = lo
            lo = hi; hi = f; st = -st
            if (hi >= lo) lo = hi - ((hi - lo)/st)*st
         else if (hi >= lo .and. hi < big) then
            hi = lo + ((hi - lo)/st)*st
         end if
      end subroutine triplet

   end function dims_overlap

   !> The longest string an assignment of variable `var` (or of its elements, 'var(i)') gives
   !> in the group, in characters (a doubled quote counts once), and the deck line of that
   !> assignment; 0 and 0 when none. The namelist reader cuts a longer string to its variable.
   pure subroutine longest_string(grp, var, length, line)
      type(group_text), intent(in) :: grp       !! the group
      character(len=*), intent(in) :: var       !! variable name, lower case
      integer, intent(out) :: length            !! characters of its longest string
      integer, intent(out) :: line              !! deck line of that assignment
      character(len=:), allocatable :: name
      integer :: i, k, n, paren
      character(len=1) :: quote

      length = 0
      line = 0
      if (.not. allocated(grp%items)) return
      do i = 1, size(grp%items)
         call item_variable(grp%items(i)%s, name)
         paren = index(name, '(')
         if (paren > 0) name = name(1:paren - 1)
         if (name /= var) cycle
         associate (item => grp%items(i)%s)
            quote = ' '
            n = 0
            k = index(item, '=') + 1
            do while (k <= len(item))
               if (quote == ' ') then
                  if (item(k:k) == '"' .or. item(k:k) == "'") then
                     quote = item(k:k)
                     n = 0
                  end if
               else if (item(k:k) == quote) then
                  if (k < len(item)) then
                     if (item(k + 1:k + 1) == quote) then   ! a doubled quote: one character
                        n = n + 1
                        k = k + 2
                        cycle
                     end if
                  end if
                  quote = ' '
                  if (n > length) then
                     length = n; line = grp%item_line(i)
                  end if
               else
                  n = n + 1
               end if
               k = k + 1
            end do
            if (quote /= ' ' .and. n > length) then   ! not closed: as long as it goes
               length = n; line = grp%item_line(i)
            end if
         end associate
      end do
   end subroutine longest_string

   !> Which elements of a variable the group's assignments give a value, read from the
   !> group's text as the namelist reader assigns them, so that "not given" is never a value:
   !> 'x = v1, v2' gives x's elements from the first on, in array element order (first
   !> subscript fastest); 'x(i) = v1, v2' from element i on (each subscript running from its
   !> value to its upper bound, as gfortran continues); 'x(l:u:s) = ...' the section's
   !> elements in its order (a subscript without ':' in a section fixed). A null value (an
   !> empty place between commas, 'r*' alone) gives none, but takes its element; 'r*c' gives
   !> r. Subscripts that are not whole numbers, of another rank or out of the bounds give
   !> nothing here (the namelist read rejects them).
   pure subroutine given_elements(grp, var, extents, given)
      type(group_text), intent(in) :: grp       !! the group
      character(len=*), intent(in) :: var       !! variable name, lower case
      integer, intent(in) :: extents(:)         !! its extents (lower bounds 1); [1] for a scalar
      logical, intent(out) :: given(:)          !! size product(extents), array element order
      character(len=:), allocatable :: name
      integer :: i
      integer :: lo(size(extents)), hi(size(extents)), step(size(extents))
      logical :: ok

      given = .false.
      if (.not. allocated(grp%items)) return
      do i = 1, size(grp%items)
         call item_variable(grp%items(i)%s, name)
         call assigned_section(name, var, extents, lo, hi, step, ok)
         if (ok) call take_values(grp%items(i)%s, lo, hi, step, extents, given)
      end do
   end subroutine given_elements

   !> The elements an assignment to `name` ('x', 'x(i, j)', 'x(l:u:s, j)') starts from and
   !> runs over, for variable `var` of these extents: each subscript from lo to hi by step
   !> (an element alone continues to the upper bounds; in a section a subscript without ':'
   !> stays fixed). ok false when the name is another variable's, or its subscripts are not
   !> whole numbers, of another rank, or start out of the bounds.
   pure subroutine assigned_section(name, var, extents, lo, hi, step, ok)
      character(len=*), intent(in) :: name      !! the assignment's variable, lower case, no blanks
      character(len=*), intent(in) :: var       !! variable name, lower case
      integer, intent(in) :: extents(:)         !! its extents (lower bounds 1); [1] for a scalar
      integer, intent(out) :: lo(:), hi(:), step(:)
      logical, intent(out) :: ok
      character(len=:), allocatable :: sub
      integer :: d, k, paren, c0, nsub
      logical :: scalar(size(extents))

      ok = .false.
      paren = index(name, '(')
      if (paren == 0) then
         if (name /= var) return
         lo = 1; hi = extents; step = 1
      else
         if (name(1:paren - 1) /= var) return
         k = index(name(paren:), ')')
         if (k == 0) return
         sub = name(paren + 1:paren + k - 2)
         if (count_char(sub, ',') + 1 /= size(extents)) return
         c0 = 1
         do d = 1, size(extents)
            nsub = index(sub(c0:), ',')
            if (nsub == 0) then
               nsub = len(sub) + 1
            else
               nsub = c0 + nsub - 1
            end if
            call subscript_section(sub(c0:nsub - 1), extents(d), lo(d), hi(d), step(d), ok)
            if (.not. ok) return
            scalar(d) = index(sub(c0:nsub - 1), ':') == 0
            c0 = nsub + 1
         end do
         ! in a section a subscript without ':' stays fixed; an element alone is continued
         if (.not. all(scalar)) where (scalar) hi = lo
      end if
      ok = .not. any(lo < 1 .or. lo > extents)
   end subroutine assigned_section

   !> One subscript: 'i' (from i to the upper bound ext) or a triplet 'l:u:s'.
   pure subroutine subscript_section(t, ext, l, u, s, ok)
      character(len=*), intent(in) :: t
      integer, intent(in) :: ext
      integer, intent(out) :: l, u, s
      logical, intent(out) :: ok
      logical :: l_given, u_given
      l = 1; u = ext; s = 1
      if (index(t, ':') == 0) then
         call int_of(t, l, ok)
         return
      end if
      call triplet_parts(t, l, u, s, l_given, u_given, ok)
      if (ok .and. s < 0) then   ! omitted bounds run the other way
         if (.not. l_given) l = ext
         if (.not. u_given) u = 1
      end if
   end subroutine subscript_section

   !> The parts of a subscript triplet 'l:u:s' (t holds a ':'): l, u and s where given, each
   !> left as it is where omitted, and whether l and u are given; ok false when a part
   !> given is not a whole number (int_of) or s is 0.
   pure subroutine triplet_parts(t, l, u, s, l_given, u_given, ok)
      character(len=*), intent(in) :: t         !! the subscript
      integer, intent(inout) :: l, u, s         !! its bounds and stride; the defaults on entry
      logical, intent(out) :: l_given, u_given  !! l and u are given
      logical, intent(out) :: ok                !! every part given is a whole number, s /= 0
      integer :: c1, c2, last
      c1 = index(t, ':')
      c2 = index(t(c1 + 1:), ':')
      if (c2 > 0) c2 = c1 + c2
      last = len(t)
      if (c2 > 0) last = c2 - 1
      l_given = c1 > 1
      u_given = last > c1
      ok = .true.
      if (l_given) call int_of(t(1:c1 - 1), l, ok)
      if (ok .and. u_given) call int_of(t(c1 + 1:last), u, ok)
      if (ok .and. c2 > 0) then
         call int_of(t(c2 + 1:), s, ok)
         if (ok) ok = s /= 0
      end if
   end subroutine triplet_parts

   !> Mark given the elements an assignment's values take, from lo on through the section
   !> (first subscript fastest): the values one at a time (next_value), each taking the next
   !> element; a null value takes its element without giving it.
   pure subroutine take_values(item, lo, hi, step, extents, given)
      character(len=*), intent(in) :: item      !! the assignment 'x(...) = v1, v2 ...'
      integer, intent(in) :: lo(:), hi(:), step(:), extents(:)
      logical, intent(inout) :: given(:)        !! size product(extents), array element order
      integer :: at(size(extents)), k, r
      logical :: more, after_comma, null, found

      at = lo
      more = all((hi - lo)*step >= 0)
      k = index(item, '=') + 1
      after_comma = .true.
      do while (more)
         call next_value(item, k, after_comma, r, null, found)
         if (.not. found) exit
         call take_elements(r, null, lo, hi, step, extents, at, more, given)
      end do
   end subroutine take_values

   !> The next r elements of a section: given, unless the values are null.
   pure subroutine take_elements(r, null, lo, hi, step, extents, at, more, given)
      integer, intent(in) :: r
      logical, intent(in) :: null
      integer, intent(in) :: lo(:), hi(:), step(:), extents(:)
      integer, intent(inout) :: at(:)      !! the element the next value takes
      logical, intent(inout) :: more       !! elements are left
      logical, intent(inout) :: given(:)
      integer :: m, e, dd, rank
      rank = size(extents)
      do m = 1, r
         if (.not. more) return
         if (.not. null .and. all(at >= 1 .and. at <= extents)) then
            e = 0
            do dd = rank, 1, -1
               e = e*extents(dd) + (at(dd) - 1)
            end do
            given(e + 1) = .true.
         end if
         ! the next element: the first subscript fastest
         more = .false.
         do dd = 1, rank
            if ((hi(dd) - (at(dd) + step(dd)))*step(dd) >= 0) then
               at(dd) = at(dd) + step(dd)
               more = .true.
               exit
            end if
            at(dd) = lo(dd)
         end do
      end do
   end subroutine take_elements

   !> The integer a subscript's text gives (an optional sign and at most 9 digits); ok false
   !> for anything else.
   pure subroutine int_of(t, v, ok)
      character(len=*), intent(in) :: t   !! the text
      integer, intent(out) :: v           !! its value (0 when not ok)
      logical, intent(out) :: ok          !! the text is such an integer
      integer :: ios, k0
      v = 0
      k0 = 1
      if (len(t) > 0) then
         if (t(1:1) == '+' .or. t(1:1) == '-') k0 = 2
      end if
      ok = len(t) >= k0 .and. len(t) <= 9
      if (ok) ok = verify(t(k0:), '0123456789') == 0
      if (.not. ok) return
      read (t, *, iostat=ios) v
      ok = ios == 0
   end subroutine int_of

   !> The variable an assignment sets, lower case, blanks removed: 'mass', 'mass(2)'.
   pure subroutine item_variable(item, var)
      character(len=*), intent(in) :: item
      character(len=:), allocatable, intent(out) :: var
      integer :: i, eq, n

      ! (counted first and allocated once: a character appended at a time reallocated the
      ! name at every character, for every assignment of every group looked up)
      eq = index(item, '=')
      n = 0
      do i = 1, eq - 1
         if (item(i:i) /= ' ' .and. item(i:i) /= achar(9)) n = n + 1
      end do
      allocate (character(len=n) :: var)
      n = 0
      do i = 1, eq - 1
         if (item(i:i) /= ' ' .and. item(i:i) /= achar(9)) then
            n = n + 1
            var(n:n) = lower(item(i:i))
         end if
      end do
   end subroutine item_variable

   !> Append a group's line (its comment blanked), from column c1, to the group's body.
   pure subroutine append_line(line, c1, body, line_of, n, lineno)
      character(len=*), intent(in) :: line
      integer, intent(in) :: c1
      character(len=*), intent(inout) :: body       !! buffer, body(1:n) used
      integer, intent(inout) :: line_of(:)          !! deck line of each character
      integer, intent(inout) :: n                   !! characters used
      integer, intent(in) :: lineno
      integer :: i

      do i = c1, len(line)
         n = n + 1
         body(n:n) = line(i:i)
         line_of(n) = lineno
      end do
      n = n + 1
      body(n:n) = ' '
      line_of(n) = lineno
   end subroutine append_line

   !> Column of the '!' that starts a line's comment (outside quotes, from column c1); 0 if
   !> the line has none.
   pure integer function comment_column(line, c1) result(col)
      character(len=*), intent(in) :: line
      integer, intent(in) :: c1
      integer :: i
      character(len=1) :: quote

      col = 0
      quote = ' '
      do i = c1, len(line)
         if (quote /= ' ') then
            if (line(i:i) == quote) quote = ' '
         else if (line(i:i) == '"' .or. line(i:i) == "'") then
            quote = line(i:i)
         else if (line(i:i) == '!') then
            col = i
            return
         end if
      end do
   end function comment_column

   !> How many values an assignment 'var = v1, v2 ...' gives, as a namelist reader counts
   !> them: separated by commas or blanks, 'r*c' and 'r*' count r, an empty place between
   !> two commas counts 1 (texts in quotes are one value).
   pure integer function value_count(item) result(nv)
      character(len=*), intent(in) :: item
      integer :: k, r
      logical :: after_comma, null, found

      nv = 0
      if (index(item, '=') == 0) return
      k = index(item, '=') + 1
      after_comma = .true.
      do
         call next_value(item, k, after_comma, r, null, found)
         if (.not. found) exit
         nv = nv + r
      end do
   end function value_count

   !> The next value of an assignment's list 'var = v1, v2 ...', as a namelist reader reads
   !> them (separated by commas or blanks, a text in quotes one value), scanning on from
   !> column k: r values ('r*c' is r values, 'r*' r null values, an empty place between two
   !> commas one null value, anything else one value). found false when the list is done.
   pure subroutine next_value(item, k, after_comma, r, null, found)
      character(len=*), intent(in) :: item      !! the assignment
      integer, intent(inout) :: k               !! where to scan on; the column after '=' at first
      logical, intent(inout) :: after_comma     !! the last separator was a comma; true at first
      integer, intent(out) :: r                 !! how many values
      logical, intent(out) :: null              !! they are null values
      logical, intent(out) :: found             !! a value was found
      integer :: t0, st, ios
      character(len=1) :: quote
      logical :: in_value

      r = 1
      null = .false.
      found = .false.
      quote = ' '
      in_value = .false.
      t0 = 0
      do while (k <= len(item) + 1)
         if (k <= len(item)) then
            if (quote /= ' ') then
               if (item(k:k) == quote) quote = ' '
               k = k + 1
               cycle
            end if
            if (item(k:k) /= ',' .and. item(k:k) /= ' ' .and. item(k:k) /= achar(9)) then
               if (item(k:k) == '"' .or. item(k:k) == "'") quote = item(k:k)
               if (.not. in_value) then
                  in_value = .true.; t0 = k
               end if
               k = k + 1
               cycle
            end if
         end if
         if (in_value) then   ! a value ends before column k: 'r*c' gives r, 'r*' is r null values
            st = index(item(t0:k - 1), '*')
            if (st > 1 .and. st <= 10) then
               if (verify(item(t0:t0 + st - 2), '0123456789') == 0) then
                  read (item(t0:t0 + st - 2), *, iostat=ios) r
                  if (ios /= 0) r = 1
                  null = t0 + st - 1 == k - 1
               end if
            end if
            after_comma = .false.
            found = .true.
            return   ! k stays on the separator
         end if
         if (k <= len(item)) then
            if (item(k:k) == ',') then
               if (after_comma) then   ! an empty place: a null value
                  null = .true.
                  found = .true.
                  k = k + 1
                  return
               end if
               after_comma = .true.
            end if
         end if
         k = k + 1
      end do
   end subroutine next_value

   !> Split a group body at the start of each 'name =' or 'name(index) ='.
   pure subroutine split_items(body, line_of, items, item_line, stat)
      character(len=*), intent(in) :: body
      integer, intent(in) :: line_of(:)
      type(line_type), allocatable, intent(out) :: items(:)
      integer, allocatable, intent(out) :: item_line(:)
      integer, intent(out) :: stat                  !! 0, or not enough memory
      integer, allocatable :: starts(:)
      integer :: i, j, depth, ns
      character(len=1) :: quote

      ! at most one assignment per '=' of the body
      allocate (starts(max(1, count_char(body, '='))), stat=stat)
      if (stat /= 0) return
      ns = 0
      quote = ' '
      do i = 1, len(body)
         if (quote /= ' ') then
            if (body(i:i) == quote) quote = ' '
            cycle
         end if
         if (body(i:i) == '"' .or. body(i:i) == "'") then
            quote = body(i:i)
            cycle
         end if
         if (body(i:i) /= '=') cycle
         ! walk back over blanks, an index and a substring in parentheses ('label(1)(1:4)'),
         ! and the name
         j = i - 1
         do while (j >= 1)
            if (body(j:j) /= ' ') exit
            j = j - 1
         end do
         do while (j >= 1)
            if (body(j:j) /= ')') exit
            depth = 0
            do while (j >= 1)
               if (body(j:j) == ')') depth = depth + 1
               if (body(j:j) == '(') depth = depth - 1
               j = j - 1
               if (depth == 0) exit
            end do
         end do
         do while (j >= 1)
            if (.not. is_name_char(body(j:j)) .and. body(j:j) /= '%') exit
            j = j - 1
         end do
         ns = ns + 1
         starts(ns) = j + 1
      end do
      allocate (items(ns), item_line(ns), stat=stat)
      if (stat /= 0) return
      do i = 1, ns
         if (i < ns) then
            items(i)%s = trim(adjustl(body(starts(i):starts(i + 1) - 1)))
         else
            items(i)%s = trim(adjustl(body(starts(i):)))
         end if
         ! drop a trailing separator comma
         j = len(items(i)%s)
         if (j > 0) then
            if (items(i)%s(j:j) == ',') items(i)%s = trim(items(i)%s(1:j - 1))
         end if
         item_line(i) = line_of(min(starts(i), size(line_of)))
      end do
   end subroutine split_items

   !> Occurrences of a character in a string.
   pure integer function count_char(str, c) result(n)
      character(len=*), intent(in) :: str
      character(len=1), intent(in) :: c
      integer :: i
      n = 0
      do i = 1, len(str)
         if (str(i:i) == c) n = n + 1
      end do
   end function count_char

   !> One assignment of a group as a namelist record of its own: '&name item /'.
   pure subroutine group_item(grp, i, record)
      type(group_text), intent(in) :: grp                  !! the group
      integer, intent(in) :: i                             !! index of the assignment
      character(len=:), allocatable, intent(out) :: record !! namelist text to read

      record = '&'//grp%name//' '//grp%items(i)%s//' /'
   end subroutine group_item

   !> After a namelist read of grp%lines (its iostat ios and iomsg msg): whether to read
   !> grp%lines again. When the whole group fails to read, grp%lines then holds each of its
   !> assignments alone in turn (group_item) until one fails, and error names it
   !> (group_read_error); if each reads alone, error gives the message on the whole group.
   !> A group reader declares the namelist and loops:
   !>
   !>     do
   !>        read (grp%lines, nml=x, iostat=ios, iomsg=msg)
   !>        call next_read(deck, grp, ios, msg, more, error)
   !>        if (.not. more) exit
   !>     end do
   !>     if (allocated(error)) return
   subroutine next_read(deck, grp, ios, msg, more, error)
      type(deck_text), intent(in) :: deck                 !! the deck
      type(group_text), intent(inout) :: grp              !! the group; its lines, the next text to read
      integer, intent(in) :: ios                          !! iostat of the read
      character(len=*), intent(inout) :: msg              !! its iomsg; blank for the next read
      logical, intent(out) :: more                        !! read grp%lines again
      type(error_type), allocatable, intent(out) :: error !! the group cannot be read
      character(len=:), allocatable :: record

      more = .false.
      if (grp%item == 0) then
         if (ios == 0) return
         grp%whole_msg = msg
      else if (ios /= 0) then
         call group_read_error(deck, grp, grp%item, msg, error); return
      end if
      if (grp%item == size(grp%items)) then
         call group_read_error(deck, grp, 0, grp%whole_msg, error); return
      end if
      grp%item = grp%item + 1
      call group_item(grp, grp%item, record)
      deallocate (grp%lines)
      allocate (character(len=len(record)) :: grp%lines(1))
      grp%lines(1) = record
      msg = ''
      more = .true.
   end subroutine next_read

   !> Error for a group that could not be read: names the assignment at fault when the
   !> one-by-one re-read found it (bad >= 1), else reports the reader's message.
   subroutine group_read_error(deck, grp, bad, msg, error)
      type(deck_text), intent(in) :: deck                 !! the deck
      type(group_text), intent(in) :: grp                 !! the group
      integer, intent(in) :: bad                          !! failing assignment, 0 if none found
      character(len=*), intent(in) :: msg                 !! the namelist reader's message
      type(error_type), allocatable, intent(out) :: error !! the error
      character(len=:), allocatable :: item, var, val
      integer :: eq, k

      if (bad < 1 .or. bad > size(grp%items)) then
         call fatal_error(error, deck%path//", group &"//grp%name//" (line "//trim(fmt_int(grp%first_line))// &
                          "): cannot be read: "//trim(msg))
         return
      end if
      item = grp%items(bad)%s
      eq = index(item, '=')
      var = trim(adjustl(item(1:max(eq - 1, 0))))
      val = trim(adjustl(item(eq + 1:)))
      ! (the reader's message holds the name, cut to its length: its start is compared)
      k = min(len(var), 64)
      if (index(msg, 'Cannot match namelist object name '//lower(var(1:k))) > 0 .or. &
          index(msg, 'Cannot match namelist object name '//var(1:k)) > 0) then
         call fatal_error(error, deck%path//", group &"//grp%name//", line "//trim(fmt_int(grp%item_line(bad)))// &
                          ": unknown variable '"//trim(fmt_text(var))//"' (value "//trim(fmt_text(val))//")")
      else
         call fatal_error(error, deck%path//", group &"//grp%name//", line "//trim(fmt_int(grp%item_line(bad)))// &
                          ": variable '"//trim(fmt_text(var))//"' has a bad value '"//trim(fmt_text(val))//"' ("// &
                          trim(fmt_text(msg))//")")
      end if
   end subroutine group_read_error

end module fd_namelist
