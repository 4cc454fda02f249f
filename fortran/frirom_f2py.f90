! The only source f2py reads. Plain subroutines with explicit-shape arrays and real(8) /
! integer(4) dummies (f2py would map a real(wp) from another module to C float). Each one
! unpacks its arguments, calls the library and returns `info` plus the library's message.
! Derived types never cross this file.

!> Text of a frirom status code.
subroutine status_message(info, msg)
    use frirom_kinds, only: ip
    use frirom_status, only: frirom_status_message
    implicit none
    integer(4), intent(in) :: info
    character(len=512), intent(out) :: msg
    msg = frirom_status_message(int(info, ip))
end subroutine status_message

! ---- contact laws and AFT ----------------------------------------------------------

! ---- harmonic balance solver -------------------------------------------------------

! ---- reduction: eigen-solves, Craig-Bampton, interface reduction -------------------
