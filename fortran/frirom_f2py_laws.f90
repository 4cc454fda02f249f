! The user-law calls for f2py (frirom_user_law): register a law callback with an open run,
! and the law code of a user-law contact group. Same rules as frirom_f2py.f90: plain
! subroutines, real(8) / integer(4) / integer(8) dummies, `info` plus the message.

!> Register with the run `handle` the C function at address fnaddr (frirom_user_law
!> user_law_fn: a ctypes CFUNCTYPE's address from Python) and its context ctxaddr (passed
!> back untouched; 0: NULL). The caller keeps both alive until the run is closed.
subroutine frun_set_user_law(handle, fnaddr, ctxaddr, info, msg)
    use, intrinsic :: iso_c_binding, only: c_funptr, c_ptr, c_intptr_t
    use frirom_kinds, only: ip
    use frirom_status, only: FRIROM_ERR_PARAM, set_status
    use frirom_run, only: run_t, run_from_handle, run_set_user_law
    use frirom_user_law, only: user_law
    implicit none
    integer(8), intent(in) :: handle, fnaddr, ctxaddr
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    type(run_t), pointer :: r
    type(c_funptr) :: fp
    type(c_ptr) :: cp
    integer(ip) :: linfo
    msg = ''
    call run_from_handle(handle, r, 'run_set_user_law', linfo, msg)
    if (linfo == 0 .and. fnaddr == 0) call set_status(linfo, FRIROM_ERR_PARAM, msg, &
                                                      'run_set_user_law: fnaddr: NULL')
    fp = transfer(int(fnaddr, c_intptr_t), fp)
    cp = transfer(int(ctxaddr, c_intptr_t), cp)
    if (linfo == 0) call run_set_user_law(r, user_law(fp, cp), linfo, msg)
    info = linfo
end subroutine frun_set_user_law

!> The law code of a user-law group with ndir directions, npar parameters and nslider
!> slider components per element (frirom_aft law_user_code; 0: out of range).
subroutine law_user_code(ndir, npar, nslider, code)
    use frirom_kinds, only: ip
    use frirom_aft, only: frirom_law_user_code => law_user_code
    implicit none
    integer(4), intent(in) :: ndir, npar, nslider
    integer(4), intent(out) :: code
    code = int(frirom_law_user_code(int(ndir, ip), int(npar, ip), int(nslider, ip)), 4)
end subroutine law_user_code
