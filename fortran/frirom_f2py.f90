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

!> Eigenpairs of K phi = lambda M phi nearest sigma (ARPACK shift-invert, MUMPS factor) and
!! static solves K x = rhs with the same (or, when sigma /= 0, a second) factor of K.
!! K and M as upper-triangle coordinates (1-based); M also as full CSR for the products.
!! nev = 0 skips the eigen-solve, nrhs = 0 the static solves.
subroutine eigen_shift_invert(n, nk, krow, kcol, kval, nm, mrow, mcol, mval, mptr, nmc, &
                              mind, mvalc, sigma, nev, lam, phi, nrhs, rhs, ncv, tol, &
                              maxiter, info, msg)
    use frirom_kinds, only: wp, ip
    use frirom_eigen, only: eigen_work, eigen_factor, eigen_solve, eigen_modes, eigen_destroy
    implicit none
    integer(4), intent(in) :: n, nk, nm, nmc, nev, nrhs, ncv, maxiter
    integer(4), intent(in) :: krow(nk), kcol(nk), mrow(nm), mcol(nm), mptr(n + 1), mind(nmc)
    real(8), intent(in) :: kval(nk), mval(nm), mvalc(nmc), sigma, tol
    real(8), intent(out) :: lam(nev), phi(n, nev)
    real(8), intent(inout) :: rhs(n, nrhs)
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    type(eigen_work) :: work
    integer(ip) :: st

    msg = ''
    info = 0
    call eigen_factor(work, int(n, ip), krow, kcol, kval, mrow, mcol, mval, real(sigma, wp), &
                      st, msg)
    if (st == 0 .and. nev > 0) then
        call eigen_modes(work, mptr, mind, mvalc, int(nev, ip), lam, phi, st, msg, &
                         ncv=int(ncv, ip), tol=real(tol, wp), maxiter=int(maxiter, ip))
    end if
    if (st == 0 .and. nrhs > 0) then
        if (sigma /= 0.0d0) then
            call eigen_factor(work, int(n, ip), krow, kcol, kval, mrow, mcol, mval, 0.0_wp, &
                              st, msg)
        end if
        if (st == 0) call eigen_solve(work, rhs, st, msg)
    end if
    call eigen_destroy(work)
    info = int(st, 4)
end subroutine eigen_shift_invert
