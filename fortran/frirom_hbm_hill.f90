!> Hill stability of frirom_hbm's periodic solutions: Floquet exponents from the
!> linearised harmonic balance equations over all DoFs x harmonics, dense (dgeev) up to
!> 2n = HILL_DENSE_MAX unknowns, shift-invert Arnoldi (ARPACK znaupd) above: on the
!> modal coordinates of a condensed system with real modes (the modal part diagonal per
!> harmonic, the contact coupling by a Woodbury identity on the contact DoFs: memory and
!> cost of the order of one Newton evaluation's), else on the banded matrices.
submodule (frirom_hbm) frirom_hbm_hill
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_ALLOC, FRIROM_ERR_LAPACK, &
                             FRIROM_ERR_SINGULAR, FRIROM_ERR_ARPACK, FRIROM_ERR_MODEL, &
                             FRIROM_ERR_PARAM, set_status
    use frirom_banded, only: band_init, band_add, band_factor, band_solve
    use frirom_arpack, only: znaupd, zneupd
    implicit none

    !> Eigenvalues Arnoldi wants per shift at first, at most.
    integer(ip), parameter :: NEV0 = 16, NEV_MAX = 256
    !> Exponents of least modulus the s = 0 route asks for (a real exponent, the resonant
    !> mode's folded pair and the nearest copies)
    integer(ip), parameter :: NEV_S0 = 8

    !> The modal Hill problem of a condensed system with real modes (T = P) at a real
    !> shift sg: unknowns q(r + nm (c-1)), slot c of mode r; Q(s) = Lam(s) + E^T Jc E,
    !> Lam per mode and harmonic [[a, b], [-b, a]] (a = w_r^2 - (h w)^2 + 2 z_r w_r s + s^2,
    !> b = h w (2 z_r w_r + 2 s)), E = phr on every slot; Q(sg)^-1 by Woodbury:
    !> Lam^-1 - Lam^-1 E^T S^-1 Jc E Lam^-1 with S = I + Jc E Lam^-1 E^T (LU in s).
    type :: modal_hill
        integer(ip) :: nm = 0, nnl = 0, nc = 0, nh = 0
        real(wp) :: w = 0.0_wp, sg = 0.0_wp
        real(wp), allocatable :: phr(:, :)    !! (nnl, nm) modes on the contact DoFs
        real(wp), allocatable :: om(:), ze(:) !! (nm) rad/s, damping ratios
        real(wp), allocatable :: jc(:, :)     !! (m, m) contact Jacobian, m = nnl nc
        real(wp), allocatable :: s(:, :)      !! (m, m) LU of S
        integer, allocatable :: ipiv(:)
    end type modal_hill

contains

    module procedure hbm_hill
        real(wp) :: w, s
        integer(ip) :: nd, n
        info = FRIROM_OK
        nd = sys%ndof
        n = nd*sys%nc
        if (size(expo) /= 2*nd) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'hbm_hill: expo needs 2 ndof')
            return
        end if
        call freq_load(sys, lam, w, s)
        select type (sys)
        type is (hbm_condensed)
            if (2*n > HILL_DENSE_MAX .and. near0_route(sys)) then
                ! the exponents nearest 0 through the Newton matrix (frirom_hbm_hill_s0),
                ! in either condensed coordinates
                call hill_near0(sys, y, lam, w, min(NEV_S0, 2*n - 2), expo, maxre, info, &
                                errmsg)
                return
            end if
            if (sys%tcontact) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'Hill stability needs '// &
                                'the condensed unknowns on the nonlinear DoFs (T = P), or '// &
                                'receptances from real modes')
                return
            end if
        end select
        ! contact Jacobians at the solution
        call hbm_contact_forces(sys, y, .true., info, errmsg)
        if (info /= 0) return
        if (2*n <= HILL_DENSE_MAX) then
            call hill_dense(sys, w, expo, maxre, info, errmsg)
            return
        end if
        select type (sys)
        type is (hbm_condensed)
            if (hill_modal_route(sys)) then
                call hill_modal(sys, w, expo, maxre, info, errmsg)
                return
            end if
        end select
        call hill_arnoldi(sys, w, expo, maxre, info, errmsg)
    end procedure hbm_hill

    !> Whether a condensed system's Hill problem above HILL_DENSE_MAX goes by hill_near0:
    !> real modes, no selection, and the whole strip not asked for (hill_strip).
    logical function near0_route(sys)
        type(hbm_condensed), intent(in) :: sys
        near0_route = sys%modal .and. allocated(sys%phr) .and. .not. allocated(sys%sel) &
                      .and. .not. sys%hill_strip
    end function near0_route

    !> Whether a condensed system's Hill problem goes by its modes (hill_modal): real
    !> modes (the same for every harmonic) and the unknowns on the contact DoFs.
    logical function hill_modal_route(sys)
        type(hbm_condensed), intent(in) :: sys
        hill_modal_route = sys%modal .and. allocated(sys%phr) .and. .not. sys%tcontact
    end function hill_modal_route

    !> The exponents of the strip |Im s| <= w/2 by shift-invert Arnoldi on the modal
    !> coordinates (modal_hill), as hill_arnoldi does on the banded matrices: memory
    !> 2 (nnl nc)^2 reals and the Arnoldi basis, not a band of every DoF.
    subroutine hill_modal(sys, w, expo, maxre, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(in) :: w
        complex(wp), intent(out) :: expo(:)
        real(wp), intent(out) :: maxre
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        type(modal_hill) :: mh
        integer(ip) :: m, nev, k, t, stat, n2
        info = FRIROM_OK
        mh%nm = size(sys%phr, 2)
        mh%nnl = sys%nnl
        mh%nc = sys%nc
        mh%nh = sys%nh
        mh%w = w
        m = mh%nnl*mh%nc
        n2 = 2*mh%nm*mh%nc
        allocate (mh%jc(m, m), mh%s(m, m), mh%ipiv(m), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'Hill (modal): contact matrices')
            return
        end if
        mh%phr = sys%phr(1:mh%nnl, :)
        mh%om = sys%wm(:, 0)
        mh%ze = sys%zm(:, 0)
        mh%jc = 0.0_wp
        call contact_assemble(sys%cs, kd=mh%jc, info=info, errmsg=errmsg, ldc=mh%nnl)
        if (info /= 0) return
        expo = cmplx(-huge(1.0_wp), 0.0_wp, wp)
        maxre = -huge(1.0_wp)
        mh%sg = 0.0_wp
        do t = 1, 2
            call modal_factor(mh, info, errmsg)
            if (info == 0) exit
            ! an exponent exactly on the shift (a fold): move the shift off the axis
            if (t == 2) return
            info = FRIROM_OK
            mh%sg = 1.0e-3_wp*w
        end do
        ! start from the count of undamped modal copies i(w_r + h w) in the disc: the
        ! contacts move them, the doubling below catches the rest
        nev = 0
        do k = -mh%nh - 1, mh%nh + 1
            nev = nev + 2*count(abs(mh%om + k*w) <= w/sqrt(2.0_wp))
        end do
        nev = min(max(NEV0, nev + 4), NEV_MAX, n2 - 2)
        call disc_exponents(cmplx(mh%sg, 0.0_wp, wp), nev, n2 - 2, w, sys%nh, expo, maxre, &
                            info, errmsg, mh=mh)
    end subroutine hill_modal

    !> a, b of Lam(sg) (see modal_hill) for every mode at harmonic h; b = 0 at h = 0.
    pure subroutine modal_ab(mh, h, a, b)
        type(modal_hill), intent(in) :: mh
        integer(ip), intent(in) :: h
        real(wp), intent(out) :: a(:), b(:)
        real(wp) :: hw
        hw = h*mh%w
        a = mh%om**2 - hw*hw + 2.0_wp*mh%ze*mh%om*mh%sg + mh%sg**2
        b = hw*(2.0_wp*mh%ze*mh%om + 2.0_wp*mh%sg)
    end subroutine modal_ab

    !> S = I + Jc R, R = E Lam(sg)^-1 E^T harmonic by harmonic (R_h = phr diag(.) phr^T),
    !> and its LU; FRIROM_ERR_SINGULAR when Lam or S is singular at sg.
    subroutine modal_factor(mh, info, errmsg)
        type(modal_hill), intent(inout) :: mh
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp), allocatable :: a(:), b(:), det(:), tmp(:, :), pa(:, :), pb(:, :)
        integer(ip) :: h, nl, m, i, c
        integer :: linfo
        info = FRIROM_OK
        nl = mh%nnl
        m = nl*mh%nc
        allocate (a(mh%nm), b(mh%nm), det(mh%nm), tmp(nl, mh%nm), pa(nl, nl), pb(nl, nl))
        mh%s = 0.0_wp
        do h = 0, mh%nh
            call modal_ab(mh, h, a, b)
            det = a*a + b*b
            if (any(det <= 0.0_wp)) then
                call set_status(info, FRIROM_ERR_SINGULAR, errmsg, 'Hill (modal): a mode '// &
                                'on the shift')
                return
            end if
            tmp = mh%phr*spread(a/det, 1, nl)
            call dgemm('N', 'T', int(nl), int(nl), int(mh%nm), 1.0_wp, tmp, int(nl), mh%phr, &
                       int(nl), 0.0_wp, pa, int(nl))
            if (h == 0) then
                call dgemm('N', 'N', int(m), int(nl), int(nl), 1.0_wp, mh%jc, int(m), pa, &
                           int(nl), 0.0_wp, mh%s, int(m))
                cycle
            end if
            tmp = mh%phr*spread(b/det, 1, nl)
            call dgemm('N', 'T', int(nl), int(nl), int(mh%nm), 1.0_wp, tmp, int(nl), mh%phr, &
                       int(nl), 0.0_wp, pb, int(nl))
            ! column blocks 2h (cos) and 2h+1 (sin): S(:, 2h) = Jc_2h Pa + Jc_2h+1 Pb,
            ! S(:, 2h+1) = -Jc_2h Pb + Jc_2h+1 Pa
            call blk(2*h, 2*h, pa, 1.0_wp, 0.0_wp)
            call blk(2*h, 2*h + 1, pb, 1.0_wp, 1.0_wp)
            call blk(2*h + 1, 2*h, pb, -1.0_wp, 0.0_wp)
            call blk(2*h + 1, 2*h + 1, pa, 1.0_wp, 1.0_wp)
        end do
        do i = 1, m
            mh%s(i, i) = mh%s(i, i) + 1.0_wp
        end do
        call dgetrf(int(m), int(m), mh%s, int(m), mh%ipiv, linfo)
        if (linfo /= 0) then
            call set_status(info, FRIROM_ERR_SINGULAR, errmsg, 'Hill (modal): I + Jc R '// &
                            'singular at the shift')
            return
        end if
    contains
        !> S(:, block cs) = beta S(:, block cs) + alpha Jc(:, block cj) p
        subroutine blk(cs, cj, p, alpha, beta)
            integer(ip), intent(in) :: cs, cj
            real(wp), intent(in) :: p(:, :), alpha, beta
            c = nl*(cs - 1) + 1
            call dgemm('N', 'N', int(m), int(nl), int(nl), alpha, mh%jc(1, nl*(cj - 1) + 1), &
                       int(m), p, int(nl), beta, mh%s(1, c), int(m))
        end subroutine blk
    end subroutine modal_factor

    !> x := Lam(sg)^-1 x for x(nm, nc, k) (k real columns).
    pure subroutine modal_lam_solve(mh, x)
        type(modal_hill), intent(in) :: mh
        real(wp), intent(inout) :: x(:, :, :)
        real(wp) :: a(mh%nm), b(mh%nm), det(mh%nm), xc(mh%nm)
        integer(ip) :: h, k
        do h = 0, mh%nh
            call modal_ab(mh, h, a, b)
            det = a*a + b*b
            do k = 1, size(x, 3)
                if (h == 0) then
                    x(:, 1, k) = x(:, 1, k)/a
                else
                    xc = x(:, 2*h, k)
                    x(:, 2*h, k) = (a*xc - b*x(:, 2*h + 1, k))/det
                    x(:, 2*h + 1, k) = (b*xc + a*x(:, 2*h + 1, k))/det
                end if
            end do
        end do
    end subroutine modal_lam_solve

    !> x := Q(sg)^-1 x for x(nm, nc, 2) (real and imaginary parts), by Woodbury.
    subroutine modal_q_solve(mh, x, info, errmsg)
        type(modal_hill), intent(in) :: mh
        real(wp), intent(inout) :: x(:, :, :)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp), allocatable :: z(:, :), t(:, :), y(:, :, :)
        integer :: nl, nm, m, nk, linfo
        info = FRIROM_OK
        nl = int(mh%nnl)
        nm = int(mh%nm)
        m = nl*int(mh%nc)
        nk = int(mh%nc)*size(x, 3)
        allocate (z(m, size(x, 3)), t(m, size(x, 3)), y(nm, mh%nc, size(x, 3)))
        call modal_lam_solve(mh, x)
        ! z = E x (every slot), t = Jc z, t := S^-1 t, y = E^T t
        call dgemm('N', 'N', nl, nk, nm, 1.0_wp, mh%phr, nl, x, nm, 0.0_wp, z, nl)
        call dgemm('N', 'N', m, size(x, 3), m, 1.0_wp, mh%jc, m, z, m, 0.0_wp, t, m)
        call dgetrs('N', m, size(x, 3), mh%s, m, mh%ipiv, t, m, linfo)
        if (linfo /= 0) then
            call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'Hill (modal): dgetrs')
            return
        end if
        call dgemm('T', 'N', nm, nk, nl, 1.0_wp, mh%phr, nl, t, nl, 0.0_wp, y, nm)
        call modal_lam_solve(mh, y)
        x = x - y
    end subroutine modal_q_solve

    !> (A - sg)^-1 [u; v] = [x; u + sg x], Q(sg) x = -(v + sg u) - D1 u on the modal
    !> coordinates (M = I; D1 = 2 z_r w_r per slot and the +-2 h w couplings).
    subroutine modal_op(mh, u, v, ox, oy, info, errmsg)
        type(modal_hill), intent(in) :: mh
        complex(wp), intent(in) :: u(:), v(:)
        complex(wp), intent(out) :: ox(:), oy(:)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        complex(wp), allocatable :: b(:, :), uu(:, :)
        real(wp), allocatable :: x(:, :, :)
        integer(ip) :: h, nm, nc, c
        nm = mh%nm
        nc = mh%nc
        uu = reshape(u, [nm, nc])
        b = -reshape(v, [nm, nc]) - mh%sg*uu
        do c = 1, nc
            b(:, c) = b(:, c) - 2.0_wp*mh%ze*mh%om*uu(:, c)
        end do
        do h = 1, mh%nh
            b(:, 2*h) = b(:, 2*h) - 2.0_wp*h*mh%w*uu(:, 2*h + 1)
            b(:, 2*h + 1) = b(:, 2*h + 1) + 2.0_wp*h*mh%w*uu(:, 2*h)
        end do
        allocate (x(nm, nc, 2))
        x(:, :, 1) = real(b, wp)
        x(:, :, 2) = aimag(b)
        call modal_q_solve(mh, x, info, errmsg)
        if (info /= 0) return
        ox = reshape(cmplx(x(:, :, 1), x(:, :, 2), wp), [nm*nc])
        oy = u + mh%sg*ox
    end subroutine modal_op

    !> All 2n exponents (dgeev with eigenvectors), then those `kept`; expo: the kept ones,
    !> then (-huge, 0).
    subroutine hill_dense(sys, w, expo, maxre, info, errmsg)
        class(hbm_system), intent(inout) :: sys
        real(wp), intent(in) :: w
        complex(wp), intent(out) :: expo(:)
        real(wp), intent(out) :: maxre
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp), allocatable :: jm(:, :), d1(:, :), md(:, :), a(:, :), wr(:), wi(:), &
                                 work(:), vr(:, :)
        complex(wp), allocatable :: p(:, :)
        real(wp) :: vl(1, 1), wq(1)
        logical :: ok
        integer(ip), allocatable :: colmap(:)
        integer(ip) :: nd, nc, n, i, k, j, c, linfo, lwork, stat, t
        info = FRIROM_OK
        nd = sys%ndof
        nc = sys%nc
        n = nd*nc
        allocate (jm(n, n), d1(n, n), md(nd, nd), a(2*n, 2*n), wr(2*n), wi(2*n), p(nc, nd), &
                  stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'Hill matrices')
            return
        end if
        ! a condensed system's G has the nl DoFs as columns
        select type (sys)
        type is (hbm_condensed)
            colmap = sys%nl
        class default
            colmap = [(i, i = 1, nd)]
        end select
        jm = 0.0_wp
        d1 = 0.0_wp
        md = 0.0_wp
        call contact_assemble(sys%cs, kd=jm, info=info, errmsg=errmsg, colmap=colmap, ldc=nd)
        if (info /= 0) return
        do i = 1, nd
            do k = sys%m%p(i), sys%m%p(i + 1) - 1
                md(i, sys%m%i(k)) = md(i, sys%m%i(k)) + sys%m%x(k)
            end do
            call hill_linear_row(sys, i, w, ok, jm=jm, d1=d1)
        end do
        ! M^-1 applied to every harmonic row block of J and D1 (Cholesky of M)
        call dpotrf('L', nd, md, nd, linfo)
        if (linfo /= 0) then
            call set_status(info, FRIROM_ERR_SINGULAR, errmsg, 'Hill: dpotrf, M not positive '// &
                            'definite')
            return
        end if
        do c = 1, nc
            call dpotrs('L', nd, n, md, nd, jm(nd*(c - 1) + 1, 1), n, linfo)
            call dpotrs('L', nd, n, md, nd, d1(nd*(c - 1) + 1, 1), n, linfo)
        end do
        a = 0.0_wp
        do i = 1, n
            a(i, n + i) = 1.0_wp
        end do
        a(n + 1:2*n, 1:n) = -jm
        a(n + 1:2*n, n + 1:2*n) = -d1
        deallocate (jm, d1)
        allocate (vr(2*n, 2*n), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'Hill eigenvectors')
            return
        end if
        call dgeev('N', 'V', 2*n, a, 2*n, wr, wi, vl, 1, vr, 2*n, wq, -1, linfo)
        lwork = int(wq(1))
        allocate (work(lwork))
        call dgeev('N', 'V', 2*n, a, 2*n, wr, wi, vl, 1, vr, 2*n, work, lwork, linfo)
        if (linfo /= 0) then
            call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'Hill: dgeev did not converge')
            return
        end if
        ! dgeev: a complex pair j, j+1 (wi(j) > 0) has eigenvectors vr(:, j) +- i vr(:, j+1)
        expo = cmplx(-huge(1.0_wp), 0.0_wp, wp)
        maxre = -huge(1.0_wp)
        k = 0
        j = 1
        do while (j <= 2*n)
            t = merge(1, 2, wi(j) == 0.0_wp)
            if (t == 1) then
                p = transpose(reshape(cmplx(vr(1:n, j), 0.0_wp, wp), [nd, nc]))
            else
                p = transpose(reshape(cmplx(vr(1:n, j), vr(1:n, j + 1), wp), [nd, nc]))
            end if
            if (kept(cmplx(wr(j), wi(j), wp), centroid(p), w, sys%nh)) then
                ! the pair's two members (conjugates, centroids of opposite sign) alike
                do i = j, j + t - 1
                    k = k + 1
                    if (k <= size(expo)) expo(k) = cmplx(wr(i), wi(i), wp)
                end do
                maxre = max(maxre, wr(j))
            end if
            j = j + t
        end do
    end subroutine hill_dense

    !> The exponents near s = 0 by shift-invert Arnoldi on the linearised problem
    !> A = [0 I; -M^-1 J, -M^-1 D1], whose (A - sigma)^-1 needs one solve with the banded
    !> Q(sigma) = J + sigma D1 + sigma^2 M (RCM order, as the full formulation); kept: those
    !> in the strip |Im s| <= w/2. The disc |s| <= w/sqrt(2) is covered (NEV_MAX exponents
    !> at most): an exponent with |Re s| > w/2 may be missed, and so are the exponents of
    !> modes above (H + 1/2) w (no copy in the strip; the dense path keeps their centred
    !> copy). expo: the kept exponents, then (-huge, 0).
    subroutine hill_arnoldi(sys, w, expo, maxre, info, errmsg)
        class(hbm_system), intent(inout) :: sys
        real(wp), intent(in) :: w
        complex(wp), intent(out) :: expo(:)
        real(wp), intent(out) :: maxre
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        type(band_matrix) :: jr, dr, mr
        type(zband_matrix) :: q
        integer(ip), allocatable :: ipc(:)
        complex(wp) :: sg
        integer(ip) :: nd, nc, n, kl, i, t
        logical :: ok
        info = FRIROM_OK
        nd = sys%ndof
        nc = sys%nc
        n = nd*nc
        kl = min(nc*(sys%bw + 1) - 1, n - 1)
        call band_init(jr, n, kl, kl, info, errmsg)
        if (info == 0) call band_init(dr, n, kl, kl, info, errmsg)
        if (info == 0) call band_init(mr, n, kl, kl, info, errmsg)
        if (info == 0) call band_init(q, n, kl, kl, info, errmsg)
        if (info /= 0) return
        ok = .true.
        do i = 1, nd
            call hill_linear_row(sys, i, w, ok, jr=jr, dr=dr, mr=mr)
        end do
        if (.not. ok) then
            call set_status(info, FRIROM_ERR_MODEL, errmsg, 'Hill: entry outside the band')
            return
        end if
        select type (sys)
        type is (hbm_condensed)
            ipc = sys%iperm(sys%nl)
        class default
            ipc = sys%iperm
        end select
        call contact_assemble(sys%cs, kb=jr, iperm=ipc, info=info, errmsg=errmsg)
        if (info /= 0) return
        expo = cmplx(-huge(1.0_wp), 0.0_wp, wp)
        maxre = -huge(1.0_wp)
        sg = (0.0_wp, 0.0_wp)
        do t = 1, 2
            q%ab = jr%ab + sg*dr%ab + sg*sg*mr%ab
            q%factored = .false.
            call band_factor(q, info, errmsg)
            if (info == 0) exit
            ! an exponent exactly on the shift (a fold): move the shift off the axis
            if (t == 2) return
            info = FRIROM_OK
            sg = cmplx(1.0e-3_wp*w, 0.0_wp, wp)
        end do
        call disc_exponents(sg, min(NEV0, 2*n - 2), 2*n - 2, w, sys%nh, expo, maxre, info, &
                            errmsg, q=q, dr=dr, mr=mr)
    end subroutine hill_arnoldi

    !> The exponents in the disc |s - sg| < w / sqrt(2) by shift_invert (banded: q, dr, mr;
    !> modal: mh), nev doubled from nev0 up to min(NEV_MAX, nmax) until the disc is covered;
    !> the kept ones (one copy of each exponent) into expo, the largest real part into maxre.
    subroutine disc_exponents(sg, nev0, nmax, w, nh, expo, maxre, info, errmsg, q, dr, mr, mh)
        complex(wp), intent(in) :: sg
        integer(ip), intent(in) :: nev0, nmax, nh
        real(wp), intent(in) :: w
        complex(wp), intent(inout) :: expo(:)
        real(wp), intent(inout) :: maxre
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        type(zband_matrix), intent(in), optional :: q
        type(band_matrix), intent(in), optional :: dr, mr
        type(modal_hill), intent(in), optional :: mh
        complex(wp), allocatable :: ev(:), vec(:, :)
        integer(ip) :: nev, nconv, nk, k
        nev = nev0
        do
            call shift_invert(sg, nev, ev, vec, nconv, info, errmsg, q=q, dr=dr, mr=mr, mh=mh)
            if (info /= 0) return
            ! enough when the disc reached covers the square |Im s|, |Re s| <= w/2
            ! (period doubling sits at its edge, Im s = w/2)
            if (nconv == 0) exit
            if (maxval(abs(ev(1:nconv))) >= w/sqrt(2.0_wp) .or. &
                nev >= min(NEV_MAX, nmax)) exit
            nev = min(2*nev, NEV_MAX, nmax)
        end do
        nk = 0
        do k = 1, nconv
            if (.not. kept(ev(k), 0.0_wp, w, nh)) cycle
            nk = nk + 1
            if (nk <= size(expo)) expo(nk) = ev(k)
            maxre = max(maxre, real(ev(k), wp))
        end do
    end subroutine disc_exponents

    !> nev eigenpairs of A nearest sigma (ev, vec(2n, nconv), converged first) by ARPACK
    !> on (A - sigma)^-1 [u; v] = [x; u + sigma x], Q(sigma) x = -M (v + sigma u) - D1 u:
    !> banded (q, dr, mr) or modal (mh, modal_op).
    subroutine shift_invert(sg, nev, ev, vec, nconv, info, errmsg, q, dr, mr, mh)
        complex(wp), intent(in) :: sg                 !! shift sigma, 1/s
        integer(ip), intent(in) :: nev
        complex(wp), allocatable, intent(out) :: ev(:)      !! (nconv) eigenvalues, 1/s
        complex(wp), allocatable, intent(out) :: vec(:, :)  !! (2n, nconv) eigenvectors
        integer(ip), intent(out) :: nconv, info
        character(len=*), intent(inout) :: errmsg
        type(zband_matrix), intent(in), optional :: q      !! Q(sigma), factored
        type(band_matrix), intent(in), optional :: dr, mr  !! D1 and M over harmonics, banded
        type(modal_hill), intent(in), optional :: mh       !! the modal problem, factored
        complex(wp), allocatable :: resid(:), v(:, :), workd(:), workl(:), workev(:), d(:), &
                                    x(:, :)
        real(wp), allocatable :: rwork(:)
        logical, allocatable :: sel(:)
        integer :: ido, iparam(11), ipntr(14), ainfo, n2, ncv, lworkl, nv
        integer(ip) :: n, k
        real(wp) :: tol
        character(len=24) :: buf
        info = FRIROM_OK
        if (present(mh)) then
            n = mh%nm*mh%nc
        else
            n = q%n
        end if
        n2 = int(2*n)
        nv = int(nev)
        ncv = int(min(2*n, max(2*nev + 1, nev + 20)))
        lworkl = 3*ncv*ncv + 5*ncv
        allocate (resid(n2), v(n2, ncv), workd(3*n2), workl(lworkl), workev(2*ncv), &
                  d(nv + 1), rwork(ncv), sel(ncv), x(n, 1))
        iparam = 0
        iparam(1) = 1           ! exact shifts
        iparam(3) = 500         ! iterations
        iparam(7) = 1           ! we apply (A - sigma)^-1 ourselves
        ipntr = 0
        ido = 0
        ainfo = 0
        tol = 1.0e-10_wp
        do
            call znaupd(ido, 'I', n2, 'LM', nv, tol, resid, ncv, v, n2, iparam, ipntr, &
                        workd, workl, lworkl, rwork, ainfo)
            if (ido /= -1 .and. ido /= 1) exit
            associate (u => workd(ipntr(1):ipntr(1) + n - 1), &
                       vv => workd(ipntr(1) + n:ipntr(1) + 2*n - 1), &
                       ox => workd(ipntr(2):ipntr(2) + n - 1), &
                       oy => workd(ipntr(2) + n:ipntr(2) + 2*n - 1))
                if (present(mh)) then
                    call modal_op(mh, u, vv, ox, oy, info, errmsg)
                    if (info /= 0) return
                    cycle
                end if
                x(:, 1) = 0.0_wp
                call band_matvec(mr, vv + sg*u, x(:, 1))
                call band_matvec(dr, u, x(:, 1))
                x = -x
                call band_solve(q, x, info, errmsg)
                if (info /= 0) return
                ox = x(:, 1)
                oy = u + sg*x(:, 1)
            end associate
        end do
        if (ainfo < 0 .or. ainfo > 1) then
            write (buf, '(i0)') ainfo
            call set_status(info, FRIROM_ERR_ARPACK, errmsg, 'Hill: znaupd info = '//trim(buf))
            return
        end if
        nconv = iparam(5)
        allocate (ev(nconv), vec(n2, max(nconv, 1)))
        if (nconv == 0) return
        call zneupd(.true., 'A', sel, d, v, n2, (0.0_wp, 0.0_wp), workev, 'I', n2, 'LM', nv, &
                    tol, resid, ncv, v, n2, iparam, ipntr, workd, workl, lworkl, rwork, ainfo)
        if (ainfo /= 0) then
            write (buf, '(i0)') ainfo
            call set_status(info, FRIROM_ERR_ARPACK, errmsg, 'Hill: zneupd info = '//trim(buf))
            return
        end if
        do k = 1, nconv
            ev(k) = sg + 1.0_wp/d(k)
            vec(:, k) = v(:, k)
        end do
    end subroutine shift_invert

    !> y += A x for a real banded A and a complex x.
    subroutine band_matvec(a, x, y)
        type(band_matrix), intent(in) :: a
        complex(wp), intent(in) :: x(:)
        complex(wp), intent(inout) :: y(:)
        integer(ip) :: i, j, d
        d = a%kl + a%ku + 1
        do j = 1, a%n
            do i = max(1_ip, j - a%ku), min(a%n, j + a%kl)
                y(i) = y(i) + a%ab(d + i - j, j)*x(j)
            end do
        end do
    end subroutine band_matvec

    !> Whether an exponent s of the truncated Hill matrix is kept: every exponent appears
    !> 2H+1 times, shifted by i h w. The AFT Jacobian of a hysteretic law linearises the
    !> slider's memory as if s were 0 (a perturbation p(t) e^(s t) recalled from the last
    !> stick onset t_s is off by e^(-s (t - t_s))), so the copy with the smallest |s|, in
    !> the strip |Im s| <= w/2, is the accurate one (the off-strip copies of a friction
    !> model can have Re s of either sign, time integration siding with the strip). A mode
    !> above (H + 1/2) w has no copy in the strip: its copy centred on harmonic 0 is kept.
    pure logical function kept(s, cen, w, nh)
        complex(wp), intent(in) :: s   !! exponent, 1/s
        real(wp), intent(in) :: cen    !! harmonic centroid of its eigenvector
        real(wp), intent(in) :: w      !! excitation frequency, rad/s
        integer(ip), intent(in) :: nh
        kept = abs(aimag(s)) <= 0.5_wp*w*(1.0_wp + 1.0e-10_wp) .or. &
               (abs(cen) <= 0.5_wp .and. abs(aimag(s)) > (nh + 0.5_wp)*w)
    end function kept

    !> Harmonic centroid sum_k k |p_k|^2 / sum_k |p_k|^2 of a Hill eigenvector over the
    !> complex harmonics k = -H..H: p(slot, DoF) with slot 1 constant, 2h cos h, 2h+1 sin h,
    !> so p_h = (p(2h) - i p(2h+1))/2 and p_-h = (p(2h) + i p(2h+1))/2.
    pure function centroid(p) result(cen)
        complex(wp), intent(in) :: p(:, :)   !! (2H+1, ndof)
        real(wp) :: cen
        real(wp) :: tot, mom, wp_, wm_
        integer(ip) :: h
        complex(wp), parameter :: im = (0.0_wp, 1.0_wp)
        tot = sum(abs(p(1, :))**2)
        mom = 0.0_wp
        do h = 1, (size(p, 1) - 1)/2
            wp_ = 0.25_wp*sum(abs(p(2*h, :) - im*p(2*h + 1, :))**2)
            wm_ = 0.25_wp*sum(abs(p(2*h, :) + im*p(2*h + 1, :))**2)
            tot = tot + wp_ + wm_
            mom = mom + h*(wp_ - wm_)
        end do
        cen = mom/max(tot, tiny(1.0_wp))
    end function centroid

    !> a(slot r of DoF i, slot c of DoF j) += alpha s(i, j) over the entries of row i of s,
    !> for a dense a whose slot c of DoF j is index j + nd (c - 1).
    !> Row i (every harmonic slot of DoF i) of the linear part of the Hill problem
    !> Q(s) = J + s D1 + s^2 M: J = K per slot, -(h w)^2 M and the +-h w C couplings of
    !> the cos/sin slots of harmonic h; D1 = C per slot and the +-2 h w M couplings; M per
    !> slot (banded only: the dense path factorises M once, apart). Into dense jm, d1
    !> (slot c of DoF j at j + ndof (c - 1)) or banded jr, dr, mr (RCM order).
    subroutine hill_linear_row(sys, i, w, ok, jm, d1, jr, dr, mr)
        class(hbm_system), intent(in) :: sys
        integer(ip), intent(in) :: i
        real(wp), intent(in) :: w
        logical, intent(inout) :: ok   !! set to .false. when an entry falls outside a band
        real(wp), intent(inout), optional :: jm(:, :), d1(:, :)
        type(band_matrix), intent(inout), optional :: jr, dr, mr
        integer(ip), parameter :: TJ = 1, TD = 2, TM = 3
        integer(ip) :: c, h
        real(wp) :: hw
        do c = 1, sys%nc
            call put(TJ, sys%k, c, c, 1.0_wp)
            call put(TD, sys%c, c, c, 1.0_wp)
            call put(TM, sys%m, c, c, 1.0_wp)
        end do
        do h = 1, sys%nh
            hw = h*w
            call put(TJ, sys%m, 2*h, 2*h, -hw*hw)
            call put(TJ, sys%m, 2*h + 1, 2*h + 1, -hw*hw)
            call put(TJ, sys%c, 2*h, 2*h + 1, hw)
            call put(TJ, sys%c, 2*h + 1, 2*h, -hw)
            call put(TD, sys%m, 2*h, 2*h + 1, 2*hw)
            call put(TD, sys%m, 2*h + 1, 2*h, -2*hw)
        end do
    contains
        !> target tgt (slot r of DoF i, slot c of DoF j) += alpha s(i, j), row i of s
        subroutine put(tgt, s, r, c, alpha)
            integer(ip), intent(in) :: tgt, r, c
            type(csr_matrix), intent(in) :: s
            real(wp), intent(in) :: alpha
            if (present(jm)) then
                if (tgt == TJ) call add_row(jm, s, sys%ndof, i, r, c, alpha)
                if (tgt == TD) call add_row(d1, s, sys%ndof, i, r, c, alpha)
            else
                if (tgt == TJ) call band_row(jr, s, sys%iperm, sys%nc, i, r, c, alpha, ok)
                if (tgt == TD) call band_row(dr, s, sys%iperm, sys%nc, i, r, c, alpha, ok)
                if (tgt == TM) call band_row(mr, s, sys%iperm, sys%nc, i, r, c, alpha, ok)
            end if
        end subroutine put
    end subroutine hill_linear_row

    pure subroutine add_row(a, s, nd, i, r, c, alpha)
        real(wp), intent(inout) :: a(:, :)
        type(csr_matrix), intent(in) :: s
        integer(ip), intent(in) :: nd, i, r, c
        real(wp), intent(in) :: alpha
        integer(ip) :: k, ia, ja
        ia = i + nd*(r - 1)
        do k = s%p(i), s%p(i + 1) - 1
            ja = s%i(k) + nd*(c - 1)
            a(ia, ja) = a(ia, ja) + alpha*s%x(k)
        end do
    end subroutine add_row

    !> The same for a banded a in RCM order: slot c of DoF j is index c + nc (iperm(j) - 1).
    pure subroutine band_row(a, s, iperm, nc, i, r, c, alpha, ok)
        type(band_matrix), intent(inout) :: a
        type(csr_matrix), intent(in) :: s
        integer(ip), intent(in) :: iperm(:), nc, i, r, c
        real(wp), intent(in) :: alpha
        logical, intent(inout) :: ok   !! set to .false. when an entry falls outside the band
        integer(ip) :: k
        do k = s%p(i), s%p(i + 1) - 1
            call band_add(a, r + nc*(iperm(i) - 1), c + nc*(iperm(s%i(k)) - 1), &
                          alpha*s%x(k), ok)
        end do
    end subroutine band_row
end submodule frirom_hbm_hill
