!> Explicit interfaces of the ARPACK routines frirom calls (reverse communication):
!> dsaupd/dseupd (symmetric, frirom_eigen's shift-invert eigen-solves), dnaupd/dneupd (real
!> nonsymmetric, Hill's exponents nearest 0: frirom_hbm_hill_s0) and znaupd/zneupd (complex,
!> Hill's strip: frirom_hbm_hill), so that every call is checked against one declaration.
module frirom_arpack
    use frirom_kinds, only: wp
    implicit none
    private
    public :: dsaupd, dseupd, dnaupd, dneupd, znaupd, zneupd

    interface
        subroutine dsaupd(ido, bmat, n, which, nev, tol, resid, ncv, v, ldv, iparam, ipntr, &
                          workd, workl, lworkl, info)
            import :: wp
            integer, intent(inout) :: ido
            character(len=1), intent(in) :: bmat
            integer, intent(in) :: n, nev, ncv, ldv, lworkl
            character(len=2), intent(in) :: which
            real(wp), intent(inout) :: tol
            real(wp), intent(inout) :: resid(n), v(ldv, ncv), workd(3*n), workl(lworkl)
            integer, intent(inout) :: iparam(11), ipntr(11), info
        end subroutine dsaupd
        subroutine dseupd(rvec, howmny, sel, d, z, ldz, sigma, bmat, n, which, nev, tol, &
                          resid, ncv, v, ldv, iparam, ipntr, workd, workl, lworkl, info)
            import :: wp
            integer, intent(in) :: ldz, n, nev, ncv, ldv, lworkl
            logical, intent(in) :: rvec
            character(len=1), intent(in) :: howmny, bmat
            logical, intent(inout) :: sel(ncv)
            real(wp), intent(out) :: d(nev), z(ldz, *)
            real(wp), intent(in) :: sigma
            character(len=2), intent(in) :: which
            real(wp), intent(inout) :: tol
            real(wp), intent(inout) :: resid(n), v(ldv, ncv), workd(2*n), workl(lworkl)
            integer, intent(inout) :: iparam(11), ipntr(11), info
        end subroutine dseupd
        subroutine znaupd(ido, bmat, n, which, nev, tol, resid, ncv, v, ldv, iparam, ipntr, &
                          workd, workl, lworkl, rwork, info)
            import :: wp
            integer, intent(inout) :: ido
            character(len=1), intent(in) :: bmat
            integer, intent(in) :: n, nev, ncv, ldv, lworkl
            character(len=2), intent(in) :: which
            real(wp), intent(inout) :: tol
            complex(wp), intent(inout) :: resid(n), v(ldv, ncv), workd(3*n), workl(lworkl)
            real(wp), intent(inout) :: rwork(ncv)
            integer, intent(inout) :: iparam(11), ipntr(14), info
        end subroutine znaupd
        subroutine zneupd(rvec, howmny, sel, d, z, ldz, sigma, workev, bmat, n, which, nev, &
                          tol, resid, ncv, v, ldv, iparam, ipntr, workd, workl, lworkl, &
                          rwork, info)
            import :: wp
            integer, intent(in) :: ldz, n, nev, ncv, ldv, lworkl
            logical, intent(in) :: rvec
            character(len=1), intent(in) :: howmny, bmat
            logical, intent(inout) :: sel(ncv)
            complex(wp), intent(out) :: d(nev + 1), z(ldz, *)
            complex(wp), intent(in) :: sigma
            complex(wp), intent(inout) :: workev(2*ncv)
            character(len=2), intent(in) :: which
            real(wp), intent(inout) :: tol
            complex(wp), intent(inout) :: resid(n), v(ldv, ncv), workd(3*n), workl(lworkl)
            real(wp), intent(inout) :: rwork(ncv)
            integer, intent(inout) :: iparam(11), ipntr(14), info
        end subroutine zneupd
        subroutine dnaupd(ido, bmat, n, which, nev, tol, resid, ncv, v, ldv, iparam, ipntr, &
                          workd, workl, lworkl, info)
            import :: wp
            integer, intent(inout) :: ido
            character(len=1), intent(in) :: bmat
            integer, intent(in) :: n, nev, ncv, ldv, lworkl
            character(len=2), intent(in) :: which
            real(wp), intent(inout) :: tol
            real(wp), intent(inout) :: resid(n), v(ldv, ncv), workd(3*n), workl(lworkl)
            integer, intent(inout) :: iparam(11), ipntr(14), info
        end subroutine dnaupd
        subroutine dneupd(rvec, howmny, sel, dr, di, z, ldz, sigmar, sigmai, workev, bmat, &
                          n, which, nev, tol, resid, ncv, v, ldv, iparam, ipntr, workd, &
                          workl, lworkl, info)
            import :: wp
            integer, intent(in) :: ldz, n, nev, ncv, ldv, lworkl
            logical, intent(in) :: rvec
            character(len=1), intent(in) :: howmny, bmat
            logical, intent(inout) :: sel(ncv)
            real(wp), intent(out) :: dr(nev + 1), di(nev + 1), z(ldz, *)
            real(wp), intent(in) :: sigmar, sigmai
            real(wp), intent(inout) :: workev(3*ncv)
            character(len=2), intent(in) :: which
            real(wp), intent(inout) :: tol
            real(wp), intent(inout) :: resid(n), v(ldv, ncv), workd(3*n), workl(lworkl)
            integer, intent(inout) :: iparam(11), ipntr(14), info
        end subroutine dneupd
    end interface
end module frirom_arpack
