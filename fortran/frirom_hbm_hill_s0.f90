!> Hill stability of a condensed system with real modes at the size of a reduced model: the
!> Floquet exponents nearest s = 0 by shift-invert Arnoldi at sigma = 0 in real arithmetic
!> (ARPACK dnaupd), every solve with Q(0) through the point solve's own factorisation.
!>
!> At s = 0 the Hill problem Q(s) = J + s D1 + s^2 M on the modal coordinates is the
!> harmonic balance Jacobian: Q(0) = Lam + E^T Jc E (Lam the modal dynamic stiffness per
!> harmonic, diagonal; E the modes on the contact DoFs; Jc = dF_c/dU). By Woodbury,
!> Q(0) x = b is x0 = Lam^-1 b, u = (I + R Jc)^-1 E x0 (R = E Lam^-1 E^T: I + R Jc is the
!> condensed Newton matrix, solved by GMRES preconditioned by the LU the solver holds, or
!> by that LU when it is J's own double LU), x = x0 - Lam^-1 E^T Jc u (Jc element by
!> element). Memory: the Arnoldi basis and one vector per unknown; no matrix of its own.
!> What it finds: the exponents of least modulus (a fold's real exponent through 0, the
!> resonant mode's folded pair near s = 0, the least damped copies); Neimark-Sacker and
!> period doubling of modes far from resonance (exponents near +-i w/2) need the strip
!> (hbm_system%hill_strip: frirom_hbm_hill's disc_exponents).
submodule (frirom_hbm:frirom_hbm_factor) frirom_hbm_hill_s0
    use frirom_status, only: FRIROM_ERR_ARPACK, itoa
    use frirom_arpack, only: dnaupd, dneupd
    implicit none

    !> GMRES on the Newton matrix: relative residual, iterations before a second try
    real(wp), parameter :: S0_GMTOL = 1.0e-11_wp
    integer(ip), parameter :: S0_GMIT = 60

contains

    module procedure hill_near0
        real(wp), allocatable :: r(:), rlam(:), resid(:), v(:, :), workd(:), workl(:), &
                                 workev(:), dr(:), di(:), zz(:, :)
        logical, allocatable :: sel(:)
        real(wp) :: rref, tol
        complex(wp) :: s
        integer :: ido, iparam(11), ipntr(14), ainfo, n2, ncv, lworkl, nv
        integer(ip) :: nm, k, nk
        info = FRIROM_OK
        ! J = I + R Jc at the solution (its LU, or GMRES on it with the LU held: cond_eval)
        allocate (r(sys%n), rlam(sys%n))
        call sys%eval(y, lam, r, rref, .true., rlam, info, errmsg)
        if (info /= 0) return
        nm = size(sys%phr, 2)
        n2 = int(2*nm*sys%nc)
        nv = int(min(nev, int(n2, ip) - 2))
        ncv = min(n2, max(2*nv + 1, nv + 20))
        lworkl = 3*ncv*ncv + 6*ncv
        allocate (resid(n2), v(n2, ncv), workd(3*n2), workl(lworkl), workev(3*ncv), &
                  dr(nv + 1), di(nv + 1), sel(ncv), zz(1, 1))
        iparam = 0
        iparam(1) = 1           ! exact shifts
        iparam(3) = 500         ! iterations
        iparam(7) = 1           ! OP = A^-1 applied here (shift-invert at sigma = 0)
        ipntr = 0
        ido = 0
        ainfo = 0
        tol = 1.0e-10_wp
        do
            call dnaupd(ido, 'I', n2, 'LM', nv, tol, resid, ncv, v, n2, iparam, ipntr, &
                        workd, workl, lworkl, ainfo)
            if (ido /= -1 .and. ido /= 1) exit
            call s0_op(sys, w, workd(ipntr(1):ipntr(1) + n2 - 1), &
                       workd(ipntr(2):ipntr(2) + n2 - 1), info, errmsg)
            if (info /= 0) return
        end do
        if (ainfo < 0 .or. ainfo > 1) then
            call set_status(info, FRIROM_ERR_ARPACK, errmsg, 'Hill (s = 0): dnaupd info = '// &
                            itoa(int(ainfo, ip)))
            return
        end if
        if (iparam(5) == 0) then
            call set_status(info, FRIROM_ERR_ARPACK, errmsg, 'Hill (s = 0): no exponent '// &
                            'converged')
            return
        end if
        call dneupd(.false., 'A', sel, dr, di, zz, 1, 0.0_wp, 0.0_wp, workev, 'I', n2, 'LM', &
                    nv, tol, resid, ncv, v, n2, iparam, ipntr, workd, workl, lworkl, ainfo)
        if (ainfo /= 0) then
            call set_status(info, FRIROM_ERR_ARPACK, errmsg, 'Hill (s = 0): dneupd info = '// &
                            itoa(int(ainfo, ip)))
            return
        end if
        expo = cmplx(-huge(1.0_wp), 0.0_wp, wp)
        maxre = -huge(1.0_wp)
        nk = 0
        do k = 1, min(iparam(5), nv)
            ! eigenvalue mu of A^-1: the exponent s = 1/mu
            s = 1.0_wp/cmplx(dr(k), di(k), wp)
            ! one copy of each exponent: the strip |Im s| <= w/2 (frirom_hbm_hill's kept)
            if (abs(aimag(s)) > 0.5_wp*w*(1.0_wp + 1.0e-10_wp)) cycle
            nk = nk + 1
            if (nk <= size(expo)) expo(nk) = s
            maxre = max(maxre, real(s, wp))
        end do
    end procedure hill_near0

    !> [ox; oy] = A^-1 [u; v] = [x; u] with Q(0) x = -v - D1 u on the modal coordinates
    !> (M = I; D1 = 2 z_r w_r per slot and the +-2 h w couplings of cos and sin slots).
    subroutine s0_op(sys, w, uv, out, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(in) :: w
        real(wp), intent(in) :: uv(:)
        real(wp), intent(out) :: out(:)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp), allocatable :: u(:, :), b(:, :)
        integer(ip) :: nm, nc, n, c, h
        associate (om => sys%wm(:, 0), ze => sys%zm(:, 0))
            nm = size(sys%phr, 2)
            nc = sys%nc
            n = nm*nc
            u = reshape(uv(1:n), [nm, nc])
            b = -reshape(uv(n + 1:2*n), [nm, nc])
            do c = 1, nc
                b(:, c) = b(:, c) - 2.0_wp*ze*om*u(:, c)
            end do
            do h = 1, sys%nh
                b(:, 2*h) = b(:, 2*h) - 2.0_wp*h*w*u(:, 2*h + 1)
                b(:, 2*h + 1) = b(:, 2*h + 1) + 2.0_wp*h*w*u(:, 2*h)
            end do
        end associate
        call s0_q_solve(sys, w, b, info, errmsg)
        if (info /= 0) return
        out(1:n) = reshape(b, [n])
        out(n + 1:2*n) = uv(1:n)
    end subroutine s0_op

    !> x := Q(0)^-1 x for x(nm, nc) by Woodbury through the Newton matrix (module head).
    subroutine s0_q_solve(sys, w, x, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(in) :: w
        real(wp), intent(inout) :: x(:, :)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp), allocatable :: z(:, :), f(:, :), y2(:, :)
        integer :: nl, nm, nc, ldp
        info = FRIROM_OK
        nl = int(sys%nnl)
        nm = size(sys%phr, 2)
        nc = int(sys%nc)
        ldp = size(sys%phr, 1)
        allocate (z(nl, nc), f(nl, nc), y2(nm, nc))
        call lam_solve(sys, w, x)
        call dgemm('N', 'N', nl, nc, nm, 1.0_wp, sys%phr, ldp, x, nm, 0.0_wp, z, nl)
        call newton_solve(sys, z, info, errmsg)
        if (info /= 0) return
        call kmul(sys, z, f, .false.)
        call dgemm('T', 'N', nm, nc, nl, 1.0_wp, sys%phr, ldp, f, nl, 0.0_wp, y2, nm)
        call lam_solve(sys, w, y2)
        x = x - y2
    end subroutine s0_q_solve

    !> x := Lam(0)^-1 x, x(nm, nc): per mode and harmonic h the slot pair (cos, sin) times
    !> [[a, b], [-b, a]]^-1, a = w_r^2 - (h w)^2, b = 2 z_r w_r h w.
    subroutine lam_solve(sys, w, x)
        type(hbm_condensed), intent(in) :: sys
        real(wp), intent(in) :: w
        real(wp), intent(inout) :: x(:, :)
        real(wp), allocatable :: a(:), b(:), det(:), xc(:)
        integer(ip) :: h
        associate (om => sys%wm(:, 0), ze => sys%zm(:, 0))
            x(:, 1) = x(:, 1)/om**2
            do h = 1, sys%nh
                a = om**2 - (h*w)**2
                b = 2.0_wp*ze*om*h*w
                det = a*a + b*b
                xc = x(:, 2*h)
                x(:, 2*h) = (a*xc - b*x(:, 2*h + 1))/det
                x(:, 2*h + 1) = (b*xc + a*x(:, 2*h + 1))/det
            end do
        end associate
    end subroutine lam_solve

    !> z := J^-1 z for the Newton matrix J = I + R Jc of the last eval (with jac): its own
    !> double LU when the eval made one, else GMRES on J (matrix-free or jcur)
    !> preconditioned by the LU held, to S0_GMTOL.
    subroutine newton_solve(sys, z, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(inout) :: z(:, :)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp), allocatable :: b(:, :)
        integer(ip) :: its
        integer :: linfo
        logical :: ok
        info = FRIROM_OK
        b = reshape(z, [sys%n, 1_ip])
        if (.not. sys%jfree .and. .not. use_krylov(sys) .and. .not. sys%held%single .and. &
            sys%lu_fresh) then
            call dgetrs('N', int(sys%n), 1, sys%jm, int(sys%n), sys%held%ipiv, b, &
                        int(sys%n), linfo)
            if (linfo /= 0) then
                call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'Hill (s = 0): dgetrs')
                return
            end if
        else
            call gmres(sys, b, its, ok, S0_GMTOL, S0_GMIT)
            if (.not. ok) call gmres(sys, b, its, ok, S0_GMTOL, 8*S0_GMIT)
            if (.not. ok) then
                call set_status(info, FRIROM_ERR_SINGULAR, errmsg, 'Hill (s = 0): GMRES '// &
                                'on the Newton matrix did not converge')
                return
            end if
        end if
        z = reshape(b, shape(z))
    end subroutine newton_solve
end submodule frirom_hbm_hill_s0
