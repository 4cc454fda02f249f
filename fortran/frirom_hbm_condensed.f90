!> The condensed formulation of frirom_hbm (Eq. 5-9 of the reference) in the coordinates
!> u = T x (T = P: the nonlinear DoFs; T = G: the contacts' local relative displacements):
!> the residual R = U - T X_e + R_h F_c(U) with the receptances R_h = T D_h^-1 T^T of
!> frirom_hbm_receptances, J = I + R_h dF_c/dU assembled element by element (dF_c/dU is
!> block diagonal per contact element), its LU or GMRES on it preconditioned by an older
!> LU, and the outputs by Eq. 9.
submodule (frirom_hbm) frirom_hbm_condensed
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_ALLOC, FRIROM_ERR_LAPACK, &
                             FRIROM_ERR_SINGULAR, FRIROM_ERR_PARAM, FRIROM_ERR_SIZE, set_status
    implicit none

    !> GMRES (Krylov mode): relative residual, iteration limit before the J is factorised,
    !> iterations above which the next J is factorised.
    real(wp), parameter :: GM_TOL = 1.0e-11_wp
    integer(ip), parameter :: GM_MAXIT = 40, GM_REFRESH = 8
    !> GMRES restart length (Krylov basis size)
    integer(ip), parameter :: GM_RESTART = 30
    !> Direct mode, modal route: the first solve after an eval with jac is GMRES on that
    !> J preconditioned by the LU held (of an older J), to this relative residual. An LU
    !> is worth lu_worth GMRES iterations (flops of each, the LU's counted
    !> LU_SPEEDUP times faster, blocked against memory-bound); J is factorised instead
    !> once the iterations since the last LU reach that, or when one solve needs more
    !> than a third of it (at least GN_MINIT); always when an LU is worth less than
    !> GN_WORTH_MIN iterations (a few hundred unknowns: LUs are cheap and each Newton
    !> path stays the one of the LUs). Deterministic: sizes and counts only.
    real(wp), parameter :: GN_TOL = 1.0e-8_wp, LU_SPEEDUP = 10.0_wp, GN_WORTH_MIN = 12.0_wp
    integer(ip), parameter :: GN_MINIT = 4
    !> GMRES iterations on a fresh single-precision LU before J is factorised in double
    integer(ip), parameter :: GS_MAXIT = 12
    !> Woodbury correction of a single LU: at most WB_PAIRS (mode, harmonic) pairs, those
    !> above WB_FLOOR times the most sensitive
    integer(ip), parameter :: WB_PAIRS = 96
    real(wp), parameter :: WB_FLOOR = 1.0e-4_wp
    !> A selected residual leaves out the modes whose terms on the kept rows sum to at most
    !> this fraction of the largest term (sel_modes, proj_safe)
    real(wp), parameter :: PROJ_SKIP = 1.0e-15_wp

contains

    module procedure cond_init
        integer(ip) :: nu, n, stat, g, e, r, k, ne_tot, ie, nk
        integer(ip), allocatable :: cols(:), seen(:)
        info = FRIROM_OK
        nu = sys%t%nrow
        sys%nnl = nu
        sys%nl = nl
        n = nu*sys%nc
        sys%n = n
        allocate (sys%ye0(sys%ndof, 0:sys%nh), sys%ye1(sys%ndof, 0:sys%nh), &
                  sys%tye0(nu, 0:sys%nh), sys%tye1(nu, 0:sys%nh), sys%ar(nu, nu, 0:sys%nh), &
                  sys%ai(nu, nu, 0:sys%nh), sys%jm(n, n), sys%ipiv(n), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'condensed: receptances/Jacobian')
            return
        end if
        ! the coordinates each contact element reads (columns of its rows of cs%g)
        ne_tot = sum([(sys%cs%grp(g)%ne, g=1, size(sys%cs%grp))])
        ! seen(col): the last element that read col (each element's columns once, in the
        ! order its rows first read them)
        allocate (sys%ecp(ne_tot + 1), cols(size(sys%cs%g%i)), seen(sys%cs%g%ncol))
        seen = 0
        sys%ecp(1) = 1
        ie = 0
        nk = 0
        do g = 1, size(sys%cs%grp)
            associate (gr => sys%cs%grp(g), gg => sys%cs%g)
                do e = 1, gr%ne
                    ie = ie + 1
                    do r = gr%row0 + (e - 1)*gr%ndir + 1, gr%row0 + e*gr%ndir
                        do k = gg%p(r), gg%p(r + 1) - 1
                            if (seen(gg%i(k)) == ie) cycle
                            seen(gg%i(k)) = ie
                            nk = nk + 1
                            cols(nk) = gg%i(k)
                        end do
                    end do
                    sys%ecp(ie + 1) = nk + 1
                end do
            end associate
        end do
        sys%ecol = cols(1:nk)
        sys%lu_any = .false.
    end procedure cond_init

    module procedure hbm_set_selection
        integer(ip) :: nu, nc, h, j, c, k, n, m, i, q, stat
        integer(ip), allocatable :: ksel(:), kpt(:), kptr(:), at(:, :), tk(:, :), ptn(:, :)
        real(wp), allocatable :: tw(:, :), jm(:, :), jk(:, :), twm(:, :)
        integer(ip), allocatable :: ipiv(:), tkm(:, :), kpr(:, :)
        logical, allocatable :: kmask(:, :)
        real(wp) :: on, off
        info = FRIROM_OK
        select type (sys => sysc)
        type is (hbm_condensed)
            nu = sys%nnl
            nc = sys%nc
            if (size(keep, 1) /= nu .or. size(keep, 2) /= sys%nh + 1) then
                call set_status(info, FRIROM_ERR_SIZE, errmsg, 'selection: keep must be '// &
                                '(nonlinear DoFs, H+1)')
            else if (sys%tcontact) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'selection: needs the '// &
                                'unknowns in the nonlinear DoFs, not in contact coordinates')
            else if (use_krylov(sys)) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'selection: needs direct '// &
                                'solves (krylov off)')
            else if (all(keep == 0)) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'selection: keeps no unknown')
            end if
            if (info /= 0) return
            if (present(pair)) then
                call check_pairs(keep, pair, ptn, info, errmsg)
                if (info /= 0) return
            end if
            ! everything is built in locals first: a failed call leaves sys as it was
            n = 0
            do c = 1, nc
                n = n + count(keep(:, c/2) /= 0)
            end do
            allocate (kptr(sys%nh + 2), kpt(count(keep /= 0)), ksel(n), at(nu, nc), &
                      tk(2, n), tw(2, n), kmask(nu, 0:sys%nh), stat=stat)
            if (stat /= 0) then
                call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'selection: index arrays')
                return
            end if
            kptr(1) = 1
            k = 0
            do h = 0, sys%nh
                do j = 1, nu
                    if (keep(j, h) == 0) cycle
                    k = k + 1
                    kpt(k) = j
                end do
                kptr(h + 2) = k + 1
            end do
            ! y: coefficient by coefficient (harmonic c/2), the kept coordinates ascending;
            ! at(j, c) its position (0: left out)
            k = 0
            at = 0
            do c = 1, nc
                h = c/2
                do i = kptr(h + 1), kptr(h + 2) - 1
                    k = k + 1
                    ksel(k) = kpt(i) + nu*(c - 1)
                    at(kpt(i), c) = k
                end do
            end do
            ! T: in the kept order, a pair's column where its first member (j, the cosine
            ! or sine of a coordinate with pair(j, h) /= 0) is, none for its second (k)
            m = 0
            do i = 1, n
                j = mod(ksel(i) - 1, nu) + 1
                c = (ksel(i) - 1)/nu + 1
                h = c/2
                m = m + 1
                tk(:, m) = [i, 0_ip]
                tw(:, m) = [1.0_wp, 0.0_wp]
                if (.not. present(pair) .or. h == 0) cycle
                if (ptn(j, h) /= 0) then
                    m = m - 1                         ! a second member: in its pair's column
                else if (pair(j, h) /= 0) then
                    q = abs(pair(j, h))
                    if (c == 2*h) then                ! (y(j, cos) + s y(q, sin)) / sqrt 2
                        tk(2, m) = at(q, c + 1)
                        tw(:, m) = [1.0_wp, real(sign(1_ip, pair(j, h)), wp)]/sqrt(2.0_wp)
                    else                              ! (y(j, sin) - s y(q, cos)) / sqrt 2
                        tk(2, m) = at(q, c - 1)
                        tw(:, m) = [1.0_wp, -real(sign(1_ip, pair(j, h)), wp)]/sqrt(2.0_wp)
                    end if
                end if
            end do
            if (m < n) then
                allocate (jk(n, m), stat=stat)
            else
                allocate (jk(0, 0), stat=stat)
            end if
            if (stat == 0) allocate (jm(m, m), ipiv(m), stat=stat)
            if (stat == 0 .and. m < n) then
                allocate (tkm(2, m), twm(2, m), kpr(nu, 0:sys%nh), stat=stat)
                if (stat == 0) then
                    tkm = tk(:, 1:m)
                    twm = tw(:, 1:m)
                    kpr = pair
                end if
            end if
            if (stat /= 0) then
                call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'selection: Jacobian')
                return
            end if
            call move_alloc(kptr, sys%kptr)
            call move_alloc(kpt, sys%kpt)
            call move_alloc(ksel, sys%sel)
            call move_alloc(jm, sys%jm)
            call move_alloc(ipiv, sys%ipiv)
            if (allocated(sys%tk)) deallocate (sys%tk, sys%tw, sys%jk, sys%kpair)
            if (m < n) then
                call move_alloc(tkm, sys%tk)
                call move_alloc(twm, sys%tw)
                call move_alloc(kpr, sys%kpair)
                call move_alloc(jk, sys%jk)
            end if
            ! the residual's mode rows (sel_rows) were cut for the selection before
            if (allocated(sys%prow)) deallocate (sys%prow)
            ! orbits hold blocks of the old T (hbm_set_orbits again)
            sys%orbits = .false.
            sys%orb_leak = 0.0_wp
            if (allocated(sys%orb)) deallocate (sys%orb)
            if (allocated(sys%kz)) deallocate (sys%kz)
            kmask = keep /= 0
            call move_alloc(kmask, sys%kmask)
            sys%n = m
            if (allocated(sys%jcur)) deallocate (sys%jcur)
            if (allocated(sys%jms)) deallocate (sys%jms)
            if (allocated(sys%kcw)) deallocate (sys%kcw)
            sys%lu_any = .false.
            sys%lu_fresh = .false.
            sys%lu_single = .false.
            sys%gm_worth = 0.0_wp
            sys%c0_leak = 0.0_wp
            sys%xe_leak = 0.0_wp
            if (allocated(sys%cs%c0)) then
                on = sum(sys%cs%c0**2, mask=keep(:, 0) /= 0)
                off = sum(sys%cs%c0**2, mask=keep(:, 0) == 0)
                sys%c0_leak = ratio(off, on)
            end if
            if (present(sel)) sel = sys%sel
        class default
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'selection: needs the '// &
                            'condensed formulation')
        end select
    end procedure hbm_set_selection

    !> Check hbm_set_selection's pair against keep: pairs at harmonics >= 1 only, between
    !> two different coordinates both kept there, each coordinate in one pair at most;
    !> ptn(k, h) = j for the second member k of j's pair, else 0.
    subroutine check_pairs(keep, pair, ptn, info, errmsg)
        integer(ip), intent(in) :: keep(:, 0:), pair(:, 0:)
        integer(ip), allocatable, intent(out) :: ptn(:, :)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: nu, nh, h, j, q, stat
        info = FRIROM_OK
        nu = size(keep, 1)
        nh = size(keep, 2) - 1
        if (size(pair, 1) /= nu .or. size(pair, 2) /= nh + 1) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'selection: pair must be '// &
                            '(nonlinear DoFs, H+1)')
            return
        end if
        allocate (ptn(nu, 0:nh), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'selection: pairs')
            return
        end if
        ptn = 0
        if (any(pair(:, 0) /= 0)) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'selection: pair at harmonic 0 '// &
                            '(it has no sine)')
            return
        end if
        do h = 1, nh
            do j = 1, nu
                q = abs(pair(j, h))
                if (q == 0) cycle
                if (q > nu .or. q == j) then
                    call set_status(info, FRIROM_ERR_PARAM, errmsg, 'selection: pair names '// &
                                    'no other coordinate')
                else if (keep(j, h) == 0 .or. keep(q, h) == 0) then
                    call set_status(info, FRIROM_ERR_PARAM, errmsg, 'selection: pair of a '// &
                                    'coordinate and harmonic left out')
                else if (pair(q, h) /= 0 .or. ptn(q, h) /= 0 .or. ptn(j, h) /= 0) then
                    call set_status(info, FRIROM_ERR_PARAM, errmsg, 'selection: a '// &
                                    'coordinate in two pairs')
                end if
                if (info /= 0) return
                ptn(q, h) = j
            end do
        end do
    end subroutine check_pairs

    module procedure hbm_sel_expand
        integer(ip) :: i
        real(wp), allocatable :: yk(:)
        select type (sys => sysc)
        type is (hbm_condensed)
            if (.not. allocated(sys%sel)) then
                yf = y
                return
            end if
            yf = 0.0_wp
            if (allocated(sys%tk)) then
                allocate (yk(size(sys%sel)))
                call pair_expand(sys, y, yk)
                yf(sys%sel) = yk
            else
                do i = 1, size(sys%sel)
                    yf(sys%sel(i)) = y(i)
                end do
            end if
        class default
            yf = y
        end select
    end procedure hbm_sel_expand

    module procedure hbm_sel_reduce
        select type (sys => sysc)
        type is (hbm_condensed)
            if (.not. allocated(sys%sel)) then
                y = yf
            else if (allocated(sys%tk)) then
                call pair_reduce(sys, yf(sys%sel), y)
            else
                y = yf(sys%sel)
            end if
        class default
            y = yf
        end select
    end procedure hbm_sel_reduce

    !> yk = T z (kept layout; hbm_condensed%tk).
    pure subroutine pair_expand(sys, z, yk)
        type(hbm_condensed), intent(in) :: sys
        real(wp), intent(in) :: z(:)
        real(wp), intent(out) :: yk(:)
        integer(ip) :: i
        yk = 0.0_wp
        do i = 1, size(sys%tk, 2)
            yk(sys%tk(1, i)) = sys%tw(1, i)*z(i)
            if (sys%tk(2, i) > 0) yk(sys%tk(2, i)) = sys%tw(2, i)*z(i)
        end do
    end subroutine pair_expand

    !> z = T^T yk (kept layout; hbm_condensed%tk).
    pure subroutine pair_reduce(sys, yk, z)
        type(hbm_condensed), intent(in) :: sys
        real(wp), intent(in) :: yk(:)
        real(wp), intent(out) :: z(:)
        integer(ip) :: i
        do i = 1, size(sys%tk, 2)
            z(i) = sys%tw(1, i)*yk(sys%tk(1, i))
            if (sys%tk(2, i) > 0) z(i) = z(i) + sys%tw(2, i)*yk(sys%tk(2, i))
        end do
    end subroutine pair_reduce

    module procedure cond_leak
        integer(ip) :: c
        real(wp) :: on, off
        leak = 0.0_wp
        if (.not. allocated(sys%sel) .or. .not. allocated(sys%fd)) return
        ! each part summed on its own: a leak at round-off is not lost to cancellation
        call fd_split(sys, on, off)
        ! the pairs: the other travelling direction counts as off the selection too
        if (allocated(sys%tk)) then
            do c = 1, sys%nh
                off = off + pair_off(sys, c, sys%fd(:, 2*c), sys%fd(:, 2*c + 1))
            end do
        end if
        leak = max(ratio(off, on), sys%c0_leak, sys%xe_leak, sys%orb_leak)
    end procedure cond_leak

    !> The squares of the contact forces sys%fd summed on the kept rows (on) and off them
    !> (off), harmonic by harmonic (a selected system).
    pure subroutine fd_split(sys, on, off)
        type(hbm_condensed), intent(in) :: sys
        real(wp), intent(out) :: on, off
        integer(ip) :: c
        on = 0.0_wp
        off = 0.0_wp
        do c = 1, sys%nc
            on = on + sum(sys%fd(:, c)**2, mask=sys%kmask(:, c/2))
            off = off + sum(sys%fd(:, c)**2, mask=.not. sys%kmask(:, c/2))
        end do
    end subroutine fd_split

    !> The part of harmonic h (cosines a, sines b by coordinate) against its pairs
    !> (hbm_condensed%kpair), squared: sum over the pairs (j, k, s) of
    !> ((a_j - s b_k)^2 + (b_j + s a_k)^2) / 2, the wave in the other direction.
    pure real(wp) function pair_off(sys, h, a, b) result(off)
        type(hbm_condensed), intent(in) :: sys
        integer(ip), intent(in) :: h
        real(wp), intent(in) :: a(:), b(:)
        integer(ip) :: j, k
        real(wp) :: s
        off = 0.0_wp
        do j = 1, sys%nnl
            k = abs(sys%kpair(j, h))
            if (k == 0) cycle
            s = real(sign(1_ip, sys%kpair(j, h)), wp)
            off = off + 0.5_wp*((a(j) - s*b(k))**2 + (b(j) + s*a(k))**2)
        end do
    end function pair_off

    !> sqrt(off / on) for two sums of squares: 0 when both are 0, huge when only on is.
    pure real(wp) function ratio(off, on)
        real(wp), intent(in) :: off, on
        if (on > 0.0_wp) then
            ratio = sqrt(off/on)
        else if (off > 0.0_wp) then
            ratio = huge(1.0_wp)
        else
            ratio = 0.0_wp
        end if
    end function ratio

    !> Whether solves go through GMRES on jcur (see hbm_condensed%krylov).
    pure logical function use_krylov(sys)
        type(hbm_condensed), intent(in) :: sys
        use_krylov = sys%krylov == 1
    end function use_krylov

    module procedure cond_eval
        real(wp) :: w, s, nx, nxe, nhf, nxd, nhd, t2(2)
        integer(ip) :: nnl, nc, h, n, nm, nhd0, nuse
        integer(ip), allocatable :: use(:)
        logical :: sel
        complex(wp), allocatable :: fc(:), z(:), dz(:), rh(:), xe(:), v(:), x3(:, :), b3(:, :)
        real(wp), allocatable :: r2(:, :), rl2(:, :)   !! (nnl, nc) r and rlam by harmonic
        real(wp), allocatable :: rf(:)                 !! (nnl nc) all rows (a selection)
        info = FRIROM_OK
        nnl = this%nnl
        nc = this%nc
        n = this%n
        call freq_load(this, lam, w, s)
        if (w /= this%w_cache) then
            call cond_receptance(this, w, info, errmsg)
            if (info /= 0) return
        end if
        call hbm_contact_forces(this, y, jac, info, errmsg, timed=.true., orbits=.true.)
        if (info /= 0) return
        allocate (fc(nnl), rh(nnl), xe(nnl), r2(nnl, nc), rl2(nnl, nc))
        if (this%modal) then
            nm = size(this%g, 1)
            allocate (v(nm), x3(nm, 3), b3(nnl, 3))
        else
            allocate (z(this%ndof), dz(this%ndof))
        end if
        nxe = 0.0_wp
        nhf = 0.0_wp
        nxd = 0.0_wp
        nhd = 0.0_wp
        nx = norm2(y)
        if (this%nrc < 0.0_wp) then
            ! |R_0 c0|: the rest forces' image, left out of fd and fe0 (contact_set), stays in
            ! the reference: the residual's scale is that of the terms before the shift. c0
            ! and R_0 (no frequency in it) are fixed once the modes are set (which reset
            ! nrc): computed once, after the first receptances
            this%nrc = 0.0_wp
            if (allocated(this%cs%c0)) then
                fc = cmplx(this%cs%c0, 0.0_wp, wp)
                if (this%modal) then
                    call modal_project(this, 0, fc, v)
                    x3(:, 1) = this%g(:, 0)*v
                    call modal_apply(this, 0, 1, nnl, x3(:, 1:1), b3(:, 1:1))
                    this%nrc = norm2(abs(b3(:, 1)))
                else
                    this%nrc = hypot(norm2(matmul(this%ar(:, :, 0), this%cs%c0)), &
                                     norm2(matmul(this%ai(:, :, 0), this%cs%c0)))
                end if
            end if
        end if
        sel = this%modal .and. allocated(this%sel) .and. allocated(this%phr)
        do h = 0, this%nh
            fc = harm_col(this%fd, h)
            if (this%modal) then
                ! T x = A g (q - A^H fc): forced part, contact part, d/dw (one product)
                if (sel) then
                    call sel_project(this, h, s, fc, v, use, nuse)
                else
                    call modal_project(this, h, fc, v)
                end if
                associate (g => this%g(:, h), q => this%qf(:, h) + s*this%qf1(:, h))
                    x3(:, 1) = g*q
                    x3(:, 2) = g*v
                    if (this%mode /= HBM_FREQUENCY) then
                        x3(:, 3) = -g*this%qf1(:, h)
                    else
                        x3(:, 3) = -this%dg(:, h)*(q - v)
                    end if
                end associate
                if (sel) then
                    ! the kept rows only (the others are dropped; cond_outputs measures the
                    ! loads' leak), over the modes that reach them
                    call rows_some(this, h, use(1:nuse), x3, b3)
                else if (allocated(this%sel)) then
                    call modal_rows(this, h, this%kpt(this%kptr(h + 1):this%kptr(h + 2) - 1), &
                                    x3, b3)
                else
                    call modal_apply(this, h, 1, nnl, x3, b3)
                end if
                xe = b3(:, 1)
                rh = b3(:, 2)
            else
                xe = this%tye0(:, h) + s*this%tye1(:, h)
                rh = cmplx(matmul(this%ar(:, :, h), real(fc, wp)) - &
                           matmul(this%ai(:, :, h), aimag(fc)), &
                           matmul(this%ar(:, :, h), aimag(fc)) + &
                           matmul(this%ai(:, :, h), real(fc, wp)), wp)
            end if
            ! |z|^2 without the square root (abs: hypot per entry)
            t2 = [sum(real(rh, wp)**2 + aimag(rh)**2), sum(real(xe, wp)**2 + aimag(xe)**2)]
            nhf = nhf + t2(1)
            nxe = nxe + t2(2)
            if (h > 0) then
                nhd = nhd + t2(1)
                nxd = nxd + t2(2)
            end if
            rh = rh - xe + harm_col(this%xd, h)
            call harm_set(r2, h, rh)
            ! dR/dlam (into xe)
            if (this%modal) then
                xe = b3(:, 3)
                if (this%mode == HBM_FREQUENCY .and. h == 0) xe = (0.0_wp, 0.0_wp)
            else if (this%mode /= HBM_FREQUENCY) then
                xe = -this%tye1(:, h)
            else if (h == 0) then
                xe = (0.0_wp, 0.0_wp)
            else
                ! z = D^-1 (fe - T^T fc); dR/dw = T D^-1 D'(w) z = Y^T D' z,
                ! D' = i h C - 2 h^2 w M (D symmetric)
                z = this%ye0(:, h) - matmul(this%ymat(:, :, h), fc)
                dz = (0.0_wp, 0.0_wp)
                call csr_matvec_add(this%c, z, dz, cmplx(0.0_wp, real(h, wp), wp))
                call csr_matvec_add(this%m, z, dz, cmplx(-2.0_wp*h*h*w, 0.0_wp, wp))
                xe = matmul(transpose(this%ymat(:, :, h)), dz)
            end if
            call harm_set(rl2, h, xe)
        end do
        if (allocated(this%sel)) then
            ! the kept rows (hbm_set_selection); y holds no harmonic 0 after its kept rows
            rf = reshape(r2, [nnl*nc])
            call hbm_sel_reduce(this, rf, r)
            rf = reshape(rl2, [nnl*nc])
            call hbm_sel_reduce(this, rf, rlam)
            nhd0 = this%kptr(2) - this%kptr(1)
        else
            r = reshape(r2, [n])
            rlam = reshape(rl2, [n])
            nhd0 = nnl
        end if
        rref = max(sqrt(nxe), nx, sqrt(nhf), this%nrc)
        ! harmonics 1..H alone (hbm_roundoff)
        this%rref_dyn = max(sqrt(nxd), norm2(y(nhd0 + 1:)), sqrt(nhd))
        if (.not. jac) return
        if (allocated(this%sel)) then
            ! the kept rows and columns only, a new LU every time (cond_jacobian_sel)
            if (this%modal) then
                this%gj = this%g
                this%wj = w
            end if
            this%jfree = .false.
            call cond_jacobian_sel(this, info, errmsg)
            return
        end if
        if (this%modal) then
            this%gj = this%g
            this%wj = w
            if (this%lu_any .and. this%gm_spent < gm_cost(this) .and. holds(this)) then
                ! J for products only, the LU stays: the next solve by GMRES (cond_solve)
                this%jfree = .true.
                this%gm_next = .true.
                this%lu_fresh = .false.
                return
            end if
            if (use_krylov(this)) then
                ! matrix-free J (jmul): R_h is formed only to factorise
                this%jfree = .true.
                this%lu_fresh = .false.
                if (this%lu_any .and. .not. this%refresh) return
            end if
            call modal_rmat(this)
        end if
        this%jfree = .false.
        call cond_jacobian(this, info, errmsg)
    end procedure cond_eval

    !> J = I + R_h dF_c/dU in real harmonic form, element by element: dF_c/dU is
    !> G_e^T J_e G_e on the coordinates S_e element e reads, so J's columns (S_e, all
    !> harmonics) receive [A_h B_h](:, S_e) times that block (R_h = A_h + i B_h); then
    !> the dense LU.
    subroutine cond_jacobian(sys, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: nu, nc, n, g, e, ie, m, h, ia, ib, s2, c2, q, col, i, mnc, nd
        integer(ip) :: d1, d2, s1, k, r, pos, stat
        real(wp), allocatable :: ge(:, :), kt(:, :), ke(:, :), wm(:, :), kab(:, :), out(:, :)
        real(wp), allocatable :: jt(:, :), kc(:, :)
        real(wp) :: t0
        logical :: krylov, dense
        info = FRIROM_OK
        t0 = wtime()
        nu = sys%nnl
        nc = sys%nc
        n = sys%n
        krylov = use_krylov(sys)
        ! elements that each read most coordinates (an interface reduced to a few
        ! generalised DoFs): dF_c/dU = G^T J_loc G assembled whole, then dense products
        dense = sum(real(sys%ecp(2:) - sys%ecp(:size(sys%ecp) - 1), wp)**2)*nc**2 > &
                real(n, wp)**2
        if (dense) then
            ! kc: the workspace kept between Jacobians (no allocation, page zeroing per call)
            stat = 0
            if (allocated(sys%kcw)) then
                if (size(sys%kcw, 1) /= n) deallocate (sys%kcw)
            end if
            if (.not. allocated(sys%kcw)) allocate (sys%kcw(n, n), stat=stat)
            if (stat == 0) call move_alloc(sys%kcw, kc)
            if (stat == 0 .and. krylov .and. .not. allocated(sys%jcur)) &
                allocate (sys%jcur(n, n), stat=stat)
        else if (krylov .and. .not. allocated(sys%jcur)) then
            allocate (sys%jcur(n, n), stat=stat)
        else
            stat = 0
        end if
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'condensed: Jacobian')
            return
        end if
        if (dense) then
            kc = 0.0_wp
            call contact_assemble(sys%cs, kd=kc, info=info, errmsg=errmsg)
            if (info /= 0) return
        end if
        if (krylov) then
            call move_alloc(sys%jcur, jt)
        else
            call move_alloc(sys%jm, jt)
        end if
        jt = 0.0_wp
        if (dense) then
            call jac_dense(sys, n, kc, jt)
            call move_alloc(kc, sys%kcw)
        end if
        ie = 0
        do g = 1, merge(0, size(sys%cs%grp), dense)   ! element by element unless dense
            associate (gr => sys%cs%grp(g), gg => sys%cs%g)
                nd = gr%ndir
                do e = 1, gr%ne
                    ie = ie + 1
                    associate (sc => sys%ecol(sys%ecp(ie):sys%ecp(ie + 1) - 1))
                        m = size(sc)
                        mnc = m*nc
                        ! G_e (nd, m) and K_e = (G_e x I)^T J_e (G_e x I), index c + nc (s-1)
                        allocate (ge(nd, m), kt(nc*nd, mnc), ke(mnc, mnc))
                        ge = 0.0_wp
                        do d1 = 1, nd
                            r = gr%row0 + (e - 1)*nd + d1
                            do k = gg%p(r), gg%p(r + 1) - 1
                                pos = findloc(sc, gg%i(k), 1)
                                ge(d1, pos) = ge(d1, pos) + gg%x(k)
                            end do
                        end do
                        kt = 0.0_wp
                        do s2 = 1, m
                            do d2 = 1, nd
                                if (ge(d2, s2) == 0.0_wp) cycle
                                kt(:, 1 + nc*(s2 - 1):nc*s2) = kt(:, 1 + nc*(s2 - 1):nc*s2) + &
                                    ge(d2, s2)*gr%jac(:, 1 + nc*(d2 - 1):nc*d2, e)
                            end do
                        end do
                        ke = 0.0_wp
                        do q = 1, mnc
                            do s1 = 1, m
                                do d1 = 1, nd
                                    if (ge(d1, s1) == 0.0_wp) cycle
                                    ke(1 + nc*(s1 - 1):nc*s1, q) = &
                                        ke(1 + nc*(s1 - 1):nc*s1, q) + &
                                        ge(d1, s1)*kt(1 + nc*(d1 - 1):nc*d1, q)
                                end do
                            end do
                        end do
                        allocate (wm(nu, 2*m), kab(2*m, 2*mnc), out(nu, 2*mnc))
                        do h = 0, sys%nh
                            if (h == 0) then
                                wm(:, 1:m) = sys%ar(:, sc, 0)
                                do s1 = 1, m
                                    kab(s1, 1:mnc) = ke(1 + nc*(s1 - 1), :)
                                end do
                                call dgemm('N', 'N', nu, mnc, m, 1.0_wp, wm, nu, kab, 2*m, &
                                           0.0_wp, out, nu)
                            else
                                ia = 2*h
                                ib = 2*h + 1
                                ! a-rows: A K_a + B K_b; b-rows: A K_b - B K_a
                                wm(:, 1:m) = sys%ar(:, sc, h)
                                wm(:, m + 1:2*m) = sys%ai(:, sc, h)
                                do s1 = 1, m
                                    kab(s1, 1:mnc) = ke(ia + nc*(s1 - 1), :)
                                    kab(m + s1, 1:mnc) = ke(ib + nc*(s1 - 1), :)
                                    kab(s1, mnc + 1:) = ke(ib + nc*(s1 - 1), :)
                                    kab(m + s1, mnc + 1:) = -ke(ia + nc*(s1 - 1), :)
                                end do
                                call dgemm('N', 'N', nu, 2*mnc, 2*m, 1.0_wp, wm, nu, kab, &
                                           2*m, 0.0_wp, out, nu)
                            end if
                            do s2 = 1, m
                                do c2 = 1, nc
                                    q = c2 + nc*(s2 - 1)
                                    col = sc(s2) + nu*(c2 - 1)
                                    if (h == 0) then
                                        jt(1:nu, col) = jt(1:nu, col) + out(:, q)
                                    else
                                        jt(nu*(ia - 1) + 1:nu*ia, col) = &
                                            jt(nu*(ia - 1) + 1:nu*ia, col) + out(:, q)
                                        jt(nu*(ib - 1) + 1:nu*ib, col) = &
                                            jt(nu*(ib - 1) + 1:nu*ib, col) + out(:, mnc + q)
                                    end if
                                end do
                            end do
                        end do
                        deallocate (ge, kt, ke, wm, kab, out)
                    end associate
                end do
            end associate
        end do
        do i = 1, n
            jt(i, i) = jt(i, i) + 1.0_wp
        end do
        sys%timers(T_ASM) = sys%timers(T_ASM) + wtime() - t0
        if (krylov) then
            call move_alloc(jt, sys%jcur)
            sys%lu_fresh = .false.
            ! keep the older LU as GMRES preconditioner unless it served badly
            if (sys%lu_any .and. .not. sys%refresh) return
        else
            call move_alloc(jt, sys%jm)
        end if
        call cond_factor(sys, info, errmsg)
    end subroutine cond_jacobian

    !> jm = R_h kc for the dense dF_c/dU kc, harmonic block by harmonic block
    !> (R_h = A + iB).
    subroutine jac_dense(sys, n, kc, jm)
        type(hbm_condensed), intent(in) :: sys
        integer(ip), intent(in) :: n
        real(wp), intent(in) :: kc(n, n)
        real(wp), intent(inout) :: jm(n, n)
        integer(ip) :: nnl, h, ca, cb
        nnl = sys%nnl
        do h = 0, sys%nh
            ca = 1
            cb = 0
            if (h > 0) then
                ca = nnl*(2*h - 1) + 1
                cb = nnl*(2*h) + 1
            end if
            call harm_rows(nnl, n, n, sys%ar(:, :, h), sys%ai(:, :, h), kc, ca, cb, jm)
        end do
    end subroutine jac_dense

    !> One harmonic's rows of J - I = R_h kc, R_h = a + i b on k coordinates, for kc's m
    !> columns: harmonic 0 (cb = 0) jm(ca.., :) = a kc(ca.., :); else a-rows A Kc_a + B Kc_b
    !> and b-rows -B Kc_a + A Kc_b (kc's and jm's rows of the cosine block from ca, the sine
    !> from cb).
    subroutine harm_rows(k, n, m, a, b, kc, ca, cb, jm)
        integer(ip), intent(in) :: k, n, m, ca, cb
        real(wp), intent(in) :: a(k, k), b(k, k), kc(n, m)
        real(wp), intent(inout) :: jm(n, m)
        call dgemm('N', 'N', k, m, k, 1.0_wp, a, k, kc(ca, 1), n, 0.0_wp, jm(ca, 1), n)
        if (cb == 0) return
        call dgemm('N', 'N', k, m, k, 1.0_wp, b, k, kc(cb, 1), n, 1.0_wp, jm(ca, 1), n)
        call dgemm('N', 'N', k, m, k, -1.0_wp, b, k, kc(ca, 1), n, 0.0_wp, jm(cb, 1), n)
        call dgemm('N', 'N', k, m, k, 1.0_wp, a, k, kc(cb, 1), n, 1.0_wp, jm(cb, 1), n)
    end subroutine harm_rows

    !> v = A^H fc (the modal route with a selection, real modes) on the modes use(1:nuse)
    !> that reach harmonic h's kept rows (sel_modes), or on all when the terms left out
    !> are not negligible against those computed (proj_safe); v is zero on the others.
    subroutine sel_project(sys, h, s, fc, v, use, nuse)
        type(hbm_condensed), intent(inout) :: sys
        integer(ip), intent(in) :: h
        real(wp), intent(in) :: s
        complex(wp), intent(in) :: fc(:)
        complex(wp), intent(out) :: v(:)
        integer(ip), allocatable, intent(inout) :: use(:)
        integer(ip), intent(out) :: nuse
        real(wp) :: skip(3)
        integer(ip) :: k
        call sel_rows(sys)
        call sel_modes(sys, h, sys%qf(:, h) + s*sys%qf1(:, h), fc, use, nuse, skip)
        if (sys%orbits) then
            call project_kept(sys, h, fc, v)
        else
            call project_some(sys, fc, use(1:nuse), v)
        end if
        if (proj_safe(sys, h, sys%qf(:, h) + s*sys%qf1(:, h), use(1:nuse), v, skip)) return
        nuse = size(v)
        use = [(k, k=1, nuse)]
        if (.not. sys%orbits) call project_some(sys, fc, use, v)
    end subroutine sel_project

    !> v = A^H fc on every mode when fc is zero off harmonic h's kept rows (the orbits'
    !> forces, T fz): over those rows only, from the cached prow, without gathering.
    subroutine project_kept(sys, h, fc, v)
        type(hbm_condensed), intent(in) :: sys
        integer(ip), intent(in) :: h
        complex(wp), intent(in) :: fc(:)
        complex(wp), intent(out) :: v(:)
        real(wp), allocatable :: fr(:, :), vr(:, :)
        integer(ip) :: lo, hi, nr, nm
        lo = sys%kptr(h + 1)
        hi = sys%kptr(h + 2) - 1
        nr = hi - lo + 1
        nm = size(sys%prow, 2)
        v = (0.0_wp, 0.0_wp)
        if (nr <= 0) return
        allocate (fr(nr, 2), vr(nm, 2))
        fr(:, 1) = real(fc(sys%kpt(lo:hi)), wp)
        fr(:, 2) = aimag(fc(sys%kpt(lo:hi)))
        call dgemm('T', 'N', nm, 2, nr, 1.0_wp, sys%prow(lo, 1), size(sys%prow, 1), fr, nr, &
                   0.0_wp, vr, nm)
        v = cmplx(vr(:, 1), vr(:, 2), wp)
    end subroutine project_kept

    !> The cache of a selection's kept mode rows (prow, pamx, pan; see hbm_condensed),
    !> (re)built when missing or made for other modes or another selection.
    subroutine sel_rows(sys)
        type(hbm_condensed), intent(inout) :: sys
        integer(ip) :: h, r, nm, a, b
        logical :: ok
        nm = size(sys%phr, 2)
        ok = allocated(sys%prow) .and. allocated(sys%prow_kpt)
        if (ok) ok = size(sys%prow_kpt) == size(sys%kpt) .and. size(sys%prow, 2) == nm
        if (ok) ok = all(sys%prow_kpt == sys%kpt)
        if (ok) return
        sys%prow = sys%phr(sys%kpt, :)
        sys%prow_kpt = sys%kpt
        if (allocated(sys%pamx)) deallocate (sys%pamx, sys%pan)
        allocate (sys%pamx(nm, 0:sys%nh), sys%pan(nm))
        do r = 1, nm
            sys%pan(r) = sum(sys%phr(1:sys%nnl, r)**2)
            do h = 0, sys%nh
                a = sys%kptr(h + 1)
                b = sys%kptr(h + 2) - 1
                sys%pamx(r, h) = 0.0_wp
                if (b >= a) sys%pamx(r, h) = maxval(sys%prow(a:b, r)**2)
            end do
        end do
    end subroutine sel_rows

    !> The modes r a selected residual needs at harmonic h: those whose terms on the kept
    !> rows, A_h(rows, r) x3(r, k) for the three columns of cond_eval (g q, g v, dg (q - v)
    !> or -g qf1; v = A^H fc), can exceed PROJ_SKIP / nm times the largest. A term is
    !> bounded by max|A(rows, r)| |g_r| |v_r| with |v_r| <= |A(:, r)| |fc| (Cauchy-
    !> Schwarz over every row: the forces off the selection count, so a mistuned rotor,
    !> whose forces there are large, keeps the modes they drive). skip(k): the sum of
    !> the left-out terms' bounds in column k, which proj_safe compares with the largest
    !> term actually computed. Every mode when a bound is not finite. The residual is then
    !> the same norm-wise (to PROJ_SKIP of its largest term), not row by row: a row much
    !> smaller than the largest may move by more than its own rounding, below rref's. The
    !> bounds are compared squared: terms below ~1e-154 (in the model's units) count as 0.
    subroutine sel_modes(sys, h, q, fc, use, nuse, skip)
        type(hbm_condensed), intent(in) :: sys
        integer(ip), intent(in) :: h
        complex(wp), intent(in) :: q(:), fc(:)
        integer(ip), allocatable, intent(inout) :: use(:)
        integer(ip), intent(out) :: nuse
        real(wp), intent(out) :: skip(3)
        real(wp), allocatable :: w(:, :)
        real(wp) :: nf2, q2, g2, t(3)
        integer(ip) :: r, nm
        nm = size(sys%phr, 2)
        if (allocated(use)) then
            if (size(use) /= nm) deallocate (use)
        end if
        if (.not. allocated(use)) allocate (use(nm))
        allocate (w(nm, 3))
        nf2 = sum(real(fc, wp)**2 + aimag(fc)**2)
        ! squared bounds
        do r = 1, nm
            q2 = sq(q(r))
            g2 = sys%pamx(r, h)*sq(sys%g(r, h))
            w(r, 1) = g2*q2
            w(r, 2) = g2*sys%pan(r)*nf2
            if (sys%mode == HBM_FREQUENCY) then
                ! (|q| + |v|)^2 <= 2 (|q|^2 + |v|^2)
                w(r, 3) = sys%pamx(r, h)*sq(sys%dg(r, h))*2.0_wp*(q2 + sys%pan(r)*nf2)
            else
                w(r, 3) = g2*sq(sys%qf1(r, h))
            end if
        end do
        t = (PROJ_SKIP/nm)**2*maxval(w, dim=1)
        skip = 0.0_wp
        nuse = 0
        if (.not. all(t < huge(1.0_wp))) then
            nuse = nm
            use = [(r, r=1, nm)]
            return
        end if
        do r = 1, nm
            if (all(w(r, :) <= t)) then
                skip = skip + sqrt(w(r, :))
                cycle
            end if
            nuse = nuse + 1
            use(nuse) = r
        end do

    contains

        !> |z|^2 without the square root
        pure real(wp) function sq(z)
            complex(wp), intent(in) :: z
            sq = real(z, wp)**2 + aimag(z)**2
        end function sq
    end subroutine sel_modes

    !> Whether the modes sel_modes left out are negligible against the terms computed:
    !> skip(k) <= PROJ_SKIP times the largest |A(rows, r) x3(r, k)| over r in use (a few
    !> units of round-off of that term, below the round-off of the sum over all modes).
    !> The columns that do not hold v (g q; -g qf1) had exact bounds: sel_modes's
    !> threshold alone keeps them. Else cond_eval takes every mode.
    logical function proj_safe(sys, h, q, use, v, skip)
        type(hbm_condensed), intent(in) :: sys
        integer(ip), intent(in) :: h, use(:)
        complex(wp), intent(in) :: q(:), v(:)
        real(wp), intent(in) :: skip(3)
        real(wp) :: big(3), a
        integer(ip) :: k, r
        big = 0.0_wp
        do k = 1, size(use)
            r = use(k)
            a = sqrt(sys%pamx(r, h))
            big(2) = max(big(2), a*abs(sys%g(r, h)*v(r)))
            big(3) = max(big(3), a*abs(sys%dg(r, h)*(q(r) - v(r))))
        end do
        proj_safe = skip(2) <= PROJ_SKIP*big(2)
        if (sys%mode == HBM_FREQUENCY) proj_safe = proj_safe .and. skip(3) <= PROJ_SKIP*big(3)
    end function proj_safe

    !> v(use) = A^H fc over the rows T (real modes phr), v zero elsewhere: the columns
    !> use of phr gathered, one product.
    subroutine project_some(sys, fc, use, v)
        type(hbm_condensed), intent(in) :: sys
        complex(wp), intent(in) :: fc(:)
        integer(ip), intent(in) :: use(:)
        complex(wp), intent(out) :: v(:)
        real(wp), allocatable :: pg(:, :), fr(:, :), vr(:, :)
        integer(ip) :: nu, k
        nu = sys%nnl
        k = size(use)
        v = (0.0_wp, 0.0_wp)
        if (k == 0) return
        allocate (fr(nu, 2), vr(k, 2))
        pg = sys%phr(1:nu, use)
        fr(:, 1) = real(fc, wp)
        fr(:, 2) = aimag(fc)
        call dgemm('T', 'N', k, 2, nu, 1.0_wp, pg, nu, fr, nu, 0.0_wp, vr, k)
        v(use) = cmplx(vr(:, 1), vr(:, 2), wp)
    end subroutine project_some

    !> modal_rows over the modes use only: b(kept rows at h, :) = A_h(those rows, use)
    !> x(use, :) from the cached rows prow; the other rows of b zero.
    subroutine rows_some(sys, h, use, x, b)
        type(hbm_condensed), intent(in) :: sys
        integer(ip), intent(in) :: h, use(:)
        complex(wp), intent(in) :: x(:, :)     !! (nm, k)
        complex(wp), intent(out) :: b(:, :)    !! (nnl, k)
        real(wp), allocatable :: pk(:, :), xr(:, :), br(:, :)
        integer(ip) :: nu, k, nr, lo, hi
        k = size(x, 2)
        nu = size(use)
        lo = sys%kptr(h + 1)
        hi = sys%kptr(h + 2) - 1
        nr = hi - lo + 1
        b = (0.0_wp, 0.0_wp)
        if (nr <= 0 .or. nu == 0) return
        pk = sys%prow(lo:hi, use)
        allocate (xr(nu, 2*k), br(nr, 2*k))
        xr(:, 1:k) = real(x(use, :), wp)
        xr(:, k + 1:) = aimag(x(use, :))
        call dgemm('N', 'N', nr, 2*k, nu, 1.0_wp, pk, nr, xr, nu, 0.0_wp, br, nr)
        b(sys%kpt(lo:hi), :) = cmplx(br(:, 1:k), br(:, k + 1:), wp)
    end subroutine rows_some

    !> Modal route, a selection: b(rows, :) = A_h(rows, :) x, the other rows of b zero.
    subroutine modal_rows(sys, h, rows, x, b)
        type(hbm_condensed), intent(in) :: sys
        integer(ip), intent(in) :: h, rows(:)
        complex(wp), intent(in) :: x(:, :)     !! (nm, k)
        complex(wp), intent(out) :: b(:, :)    !! (nnl, k)
        real(wp), allocatable :: pk(:, :), xr(:, :), br(:, :)
        complex(wp), allocatable :: zk(:, :), bk(:, :)
        integer(ip) :: nm, k, nr
        nm = size(x, 1)
        k = size(x, 2)
        nr = size(rows)
        b = (0.0_wp, 0.0_wp)
        if (nr == 0) return
        if (allocated(sys%phr)) then
            pk = sys%phr(rows, :)
            allocate (xr(nm, 2*k), br(nr, 2*k))
            xr(:, 1:k) = real(x, wp)
            xr(:, k + 1:) = aimag(x)
            call dgemm('N', 'N', nr, 2*k, nm, 1.0_wp, pk, nr, xr, nm, 0.0_wp, br, nr)
            b(rows, :) = cmplx(br(:, 1:k), br(:, k + 1:), wp)
        else
            zk = sys%psi(rows, :, h)
            allocate (bk(nr, k))
            call zgemm('N', 'N', nr, k, nm, (1.0_wp, 0.0_wp), zk, nr, x, nm, &
                       (0.0_wp, 0.0_wp), bk, nr)
            b(rows, :) = bk
        end if
    end subroutine modal_rows

    !> J of a selected system (hbm_set_selection) on its kept rows and columns: kc, the
    !> kept part of dF_c/dU in y's order, by products over each contact group's dense
    !> rows (gr%gt) or taken from the element loops, then J = I + R_h kc with R_h on the
    !> coordinates kept at harmonic h only (exact for a tuned rotor, whose R_h does not
    !> couple the index families), then the LU.
    subroutine cond_jacobian_sel(sys, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: n, nu, nc, g, h, c, kh, ca, cb, stat, i, nk
        integer(ip), allocatable :: at(:), off(:), zc(:)
        real(wp), allocatable :: kc(:, :), kf(:, :), a(:, :), b(:, :), zw(:), kz(:, :)
        logical :: paired
        real(wp) :: t0
        logical :: dense
        info = FRIROM_OK
        t0 = wtime()
        n = sys%n
        nk = size(sys%sel)
        nu = sys%nnl
        nc = sys%nc
        paired = allocated(sys%tk)
        stat = 0
        dense = .true.
        do g = 1, size(sys%cs%grp)
            if (sys%cs%grp(g)%asm_mode == 0) call choose_dense(sys%cs%grp(g), sys%cs%g)
            dense = dense .and. sys%cs%grp(g)%asm_mode == 2
        end do
        ! kc on the kept columns, or with pairs and dense rows (or orbits) straight on T's
        ! (kc T)
        i = nk
        if (paired .and. (dense .or. sys%orbits)) i = n
        if (allocated(sys%kcw)) then
            if (size(sys%kcw, 2) /= i) deallocate (sys%kcw)
        end if
        if (.not. allocated(sys%kcw)) allocate (sys%kcw(nk, i), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'condensed: Jacobian')
            return
        end if
        call move_alloc(sys%kcw, kc)
        ! at: position j + nu (c-1) -> its index in y (0: left out); off(c): y's entries
        ! before coefficient c
        allocate (at(nu*nc), off(nc + 1), zc(nk), zw(nk), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'condensed: Jacobian')
            call move_alloc(kc, sys%kcw)
            return
        end if
        at = 0
        at(sys%sel) = [(i, i=1, nk)]
        ! zc(k), zw(k): T's column that holds kept unknown k, and its weight there
        if (paired) then
            do i = 1, n
                do c = 1, 2
                    if (sys%tk(c, i) == 0) cycle
                    zc(sys%tk(c, i)) = i
                    zw(sys%tk(c, i)) = sys%tw(c, i)
                end do
            end do
        end if
        off(1) = 0
        do c = 1, nc
            h = c/2
            off(c + 1) = off(c) + sys%kptr(h + 2) - sys%kptr(h + 1)
        end do
        kc = 0.0_wp
        if (sys%orbits) then
            ! the orbits' T^T dF_c/dU T (kz): kc T = T kz, the wave's forces staying on it
            do i = 1, n
                do c = 1, 2
                    if (sys%tk(c, i) == 0) cycle
                    kc(sys%tk(c, i), :) = sys%tw(c, i)*sys%kz(i, :)
                end do
            end do
        else if (dense) then
            do g = 1, size(sys%cs%grp)
                if (paired) then
                    call kc_dense_sel(sys%cs%grp(g), nu, nc, at, kc, zc, zw)
                else
                    call kc_dense_sel(sys%cs%grp(g), nu, nc, at, kc)
                end if
            end do
        else
            ! sparse rows (physical contact DoFs, not what a selection is for): the element
            ! loops of contact_assemble in the full layout, then the kept part
            allocate (kf(nu*nc, nu*nc), stat=stat)
            if (stat == 0) then
                kf = 0.0_wp
                call contact_assemble(sys%cs, kd=kf, info=info, errmsg=errmsg, loops=.true.)
                kc = kf(sys%sel, sys%sel)
            else
                call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'condensed: Jacobian')
            end if
            if (info /= 0) then
                call move_alloc(kc, sys%kcw)
                return
            end if
        end if
        if (paired .and. .not. (dense .or. sys%orbits)) then
            ! kz = kc T: R_h's products then on T's columns only
            allocate (kz(nk, n), stat=stat)
            if (stat /= 0) then
                call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'condensed: Jacobian')
                call move_alloc(kc, sys%kcw)
                return
            end if
            kz = 0.0_wp
            do i = 1, nk
                kz(:, zc(i)) = kz(:, zc(i)) + zw(i)*kc(:, i)
            end do
            call move_alloc(kz, kc)
        end if
        sys%timers(T_ASM) = sys%timers(T_ASM) + wtime() - t0
        do h = 0, sys%nh
            kh = sys%kptr(h + 2) - sys%kptr(h + 1)
            if (kh == 0) cycle
            call rec_block(sys, h, sys%kpt(sys%kptr(h + 1):sys%kptr(h + 2) - 1), a, b)
            t0 = wtime()
            ca = off(1) + 1
            cb = 0
            if (h > 0) then
                ca = off(2*h) + 1
                cb = off(2*h + 1) + 1
            end if
            if (paired) then
                call harm_rows(kh, nk, n, a, b, kc, ca, cb, sys%jk)
            else
                call harm_rows(kh, nk, n, a, b, kc, ca, cb, sys%jm)
            end if
            sys%timers(T_ASM) = sys%timers(T_ASM) + wtime() - t0
        end do
        call move_alloc(kc, sys%kcw)
        ! pairs: J_z = T^T (J T) (I stays I, T orthonormal)
        if (paired) call pair_rows(sys)
        do i = 1, n
            sys%jm(i, i) = sys%jm(i, i) + 1.0_wp
        end do
        call cond_factor(sys, info, errmsg)
    end subroutine cond_jacobian_sel

    !> jm = T^T jk for a selection with pairs (hbm_condensed%tk; jk = J T): the rows.
    subroutine pair_rows(sys)
        type(hbm_condensed), intent(inout) :: sys
        integer(ip) :: i, j
        real(wp) :: t0
        t0 = wtime()
        do j = 1, sys%n
            do i = 1, sys%n
                sys%jm(i, j) = sys%tw(1, i)*sys%jk(sys%tk(1, i), j)
                if (sys%tk(2, i) > 0) sys%jm(i, j) = sys%jm(i, j) + &
                                                     sys%tw(2, i)*sys%jk(sys%tk(2, i), j)
            end do
        end do
        sys%timers(T_ASM) = sys%timers(T_ASM) + wtime() - t0
    end subroutine pair_rows

    !> R_h = a + i b on the coordinates rows (both sides), at the Jacobian's frequency:
    !> from the modes (A_h(rows) diag(g_h) A_h(rows)^H, only these rows) or read from the
    !> factorised receptances ar, ai. With real modes rows must be harmonic h's kept rows
    !> (kpt(kptr(h+1):kptr(h+2)-1)): their mode rows come from the selection's cache
    !> (sel_rows' prow and pamx) instead of being gathered from phr.
    subroutine rec_block(sys, h, rows, a, b)
        type(hbm_condensed), intent(inout) :: sys
        integer(ip), intent(in) :: h, rows(:)
        real(wp), allocatable, intent(out) :: a(:, :), b(:, :)
        real(wp), allocatable :: p(:, :), pd(:, :)
        complex(wp), allocatable :: z(:, :), zd(:, :), rz(:, :)
        integer(ip), allocatable :: use(:)
        integer(ip) :: k, nm, r
        real(wp) :: t0
        t0 = wtime()
        k = size(rows)
        allocate (a(k, k), b(k, k))
        if (.not. sys%modal) then
            a = sys%ar(rows, rows, h)
            b = sys%ai(rows, rows, h)
        else if (allocated(sys%phr)) then
            ! only the modes that reach these rows (a tuned rotor's family ROM: about a
            ! quarter at each harmonic), the others' terms below the products' round-off
            call sel_rows(sys)
            call modes_on_rows(sys%pamx(:, h), sys%gj(:, h), use, nm)
            p = sys%prow(sys%kptr(h + 1):sys%kptr(h + 2) - 1, use(1:nm))
            allocate (pd(k, 2*nm + 1))
            do r = 1, nm
                pd(:, r) = p(:, r)*real(sys%gj(use(r), h), wp)
                pd(:, nm + r) = p(:, r)*aimag(sys%gj(use(r), h))
            end do
            call dgemm('N', 'T', k, k, nm, 1.0_wp, pd, k, p, k, 0.0_wp, a, k)
            call dgemm('N', 'T', k, k, nm, 1.0_wp, pd(1, nm + 1), k, p, k, 0.0_wp, b, k)
        else
            nm = size(sys%gj, 1)
            z = sys%psi(rows, :, h)
            allocate (zd(k, nm), rz(k, k))
            do r = 1, nm
                zd(:, r) = z(:, r)*sys%gj(r, h)
            end do
            call zgemm('N', 'C', k, k, nm, (1.0_wp, 0.0_wp), zd, k, z, k, (0.0_wp, 0.0_wp), &
                       rz, k)
            a = real(rz, wp)
            b = aimag(rz)
        end if
        sys%timers(T_REC) = sys%timers(T_REC) + wtime() - t0
    end subroutine rec_block

    !> The modes r whose term g_r p_r p_r^T of R = P diag(g) P^T on some rows exceeds
    !> REC_SKIP times the largest term (pm2(r) |g_r|, pm2(r) = max over the rows of p_r^2):
    !> use(1:nu). A term left out is below the round-off of the sum over all nm modes (~nm
    !> eps the largest term), so R is the same to round-off; rows a mode does not reach at
    !> all are zero.
    subroutine modes_on_rows(pm2, g, use, nu)
        real(wp), intent(in) :: pm2(:)
        complex(wp), intent(in) :: g(:)
        integer(ip), allocatable, intent(out) :: use(:)
        integer(ip), intent(out) :: nu
        real(wp), parameter :: REC_SKIP = 1.0e-14_wp
        real(wp), allocatable :: w(:)
        real(wp) :: wmin
        integer(ip) :: r
        allocate (w(size(pm2)), use(size(pm2)))
        do r = 1, size(pm2)
            w(r) = pm2(r)*abs(g(r))
        end do
        wmin = REC_SKIP*maxval(w)
        ! a non-finite term (an undamped mode at resonance) gives no scale: every mode
        if (.not. wmin < huge(1.0_wp)) wmin = -1.0_wp
        nu = 0
        do r = 1, size(pm2)
            if (w(r) <= wmin .or. (w(r) == 0.0_wp .and. wmin >= 0.0_wp)) cycle
            nu = nu + 1
            use(nu) = r
        end do
    end subroutine modes_on_rows

    !> kc += the kept part of G_g^T J_loc G_g for a group with dense rows over its columns
    !> (gt = Gd^T, gcols): per coefficient c1, the kept columns S1 of the group at c1 and
    !> all kept (column, c2) Q: kc(S1 c1, Q) += Gd(:, S1)^T Y, Y = J_loc Gd on Q, direction
    !> by direction over the columns that direction's rows read. Those are a range: each
    !> coefficient's columns are ordered by the directions that read them (an MS
    !> coordinate is one cylindrical component: a normal or a tangential row reads a third).
    subroutine kc_dense_sel(gr, nu, nc, at, kc, zc, zw)
        type(contact_group), intent(in) :: gr
        integer(ip), intent(in) :: nu, nc, at(:)
        real(wp), intent(inout) :: kc(:, :)
        !> a selection's pairs: kc is then (kept, T's columns) and gets kc T
        !> (kc_dense_pairs); zc(k) the column of T that holds kept unknown k, zw(k) its
        !> weight there
        integer(ip), intent(in), optional :: zc(:)
        real(wp), intent(in), optional :: zw(:)
        integer(ip), allocatable :: ls(:, :), py(:, :), ln(:), qoff(:), key(:), ord(:), &
                                    lo(:, :), hi(:, :), pq(:)
        real(wp), allocatable :: yt(:, :, :), gs(:, :, :), kt(:, :)
        logical, allocatable :: rd(:, :)
        !> two directions, by the mask of those that read a column: d1 only, both, d2 only,
        !> none (each direction's columns are then one range)
        integer(ip), parameter :: ORDER2(0:3) = [3, 0, 2, 1]
        integer(ip) :: ns, nd, ne, nrg, c, c1, c2, d1, d2, e, s, m1, nq, p, k, a, b
        real(wp) :: v
        nd = gr%ndir
        ne = gr%ne
        nrg = ne*nd
        ns = size(gr%gcols)
        ! rd(s, d): direction d's rows read column s; key: the order of the columns within
        ! a coefficient (more than two directions: a range may hold columns it does not read)
        allocate (rd(ns, nd), key(ns), ord(ns))
        do d1 = 1, nd
            rd(:, d1) = any(gr%gt(:, d1:nrg:nd) /= 0.0_wp, dim=2)
        end do
        do s = 1, ns
            key(s) = sum([(merge(2**(d1 - 1), 0, rd(s, d1)), d1=1, nd)])
            if (nd == 2) key(s) = ORDER2(key(s))
        end do
        k = 0
        do p = 0, maxval(key)
            do s = 1, ns
                if (key(s) /= p) cycle
                k = k + 1
                ord(k) = s
            end do
        end do
        ! ls(:, c): the group's columns (index into gcols) kept at coefficient c in that
        ! order, py their indices in y, lo:hi(c, d) those direction d reads
        allocate (ls(ns, nc), py(ns, nc), ln(nc), qoff(nc + 1), lo(nc, nd), hi(nc, nd))
        qoff(1) = 0
        do c = 1, nc
            ln(c) = 0
            lo(c, :) = 1
            hi(c, :) = 0
            do k = 1, ns
                s = ord(k)
                p = at(gr%gcols(s) + nu*(c - 1))
                if (p == 0) cycle
                ln(c) = ln(c) + 1
                ls(ln(c), c) = s
                py(ln(c), c) = p
                do d1 = 1, nd
                    if (.not. rd(s, d1)) cycle
                    if (hi(c, d1) == 0) lo(c, d1) = ln(c)
                    hi(c, d1) = ln(c)
                end do
            end do
            qoff(c + 1) = qoff(c) + ln(c)
        end do
        nq = qoff(nc + 1)
        if (nq == 0) return
        ! gs(q, e, d): Gd^T on Q (the kept columns of every coefficient stacked), by direction
        allocate (gs(nq, ne, nd))
        do d1 = 1, nd
            do c = 1, nc
                gs(qoff(c) + 1:qoff(c + 1), :, d1) = gr%gt(ls(1:ln(c), c), d1:nrg:nd)
            end do
        end do
        if (present(zc)) then
            call kc_dense_pairs(gr, nc, ln, qoff, ls, py, lo, hi, rd, key, gs, zc, zw, kc)
            return
        end if
        allocate (yt(nq, ne, nd), kt(maxval(ln), nq), pq(nq))
        do c = 1, nc
            pq(qoff(c) + 1:qoff(c + 1)) = py(1:ln(c), c)
        end do
        do c1 = 1, nc
            m1 = ln(c1)
            if (m1 == 0) cycle
            yt = 0.0_wp
            do d1 = 1, nd
                do e = 1, ne
                    do c2 = 1, nc
                        do d2 = 1, nd
                            v = gr%jac(c1 + nc*(d1 - 1), c2 + nc*(d2 - 1), e)
                            if (v == 0.0_wp .or. hi(c2, d2) == 0) cycle
                            a = qoff(c2) + lo(c2, d2)
                            b = qoff(c2) + hi(c2, d2)
                            yt(a:b, e, d1) = yt(a:b, e, d1) + v*gs(a:b, e, d2)
                        end do
                    end do
                end do
            end do
            call rows_into(nq, ne, nd, nq, size(kt, 1), gs, c1, m1, lo, hi, qoff, yt, &
                           py(:, c1), pq, kt, kc)
        end do
    end subroutine kc_dense_sel

    !> kc_dense_sel for a selection's pairs: kc(S1 c1, z) += Gd(:, S1)^T Y_z, Y_z = J_loc
    !> Gd T on T's columns z that touch the group (one or two members in Q, a pair's in
    !> coefficients c and c + 1), the products then on half the columns. The z are grouped
    !> by their members' coefficients (ca, cb), so that J_loc's two entries are the same
    !> for a group, and ordered within it by the directions that read them: Y_z is formed
    !> from gs1 = zw Gd^T on the first members and gs2 on the second, range by range.
    subroutine kc_dense_pairs(gr, nc, ln, qoff, ls, py, lo, hi, rd, key, gs, zc, zw, kc)
        type(contact_group), intent(in) :: gr
        integer(ip), intent(in) :: nc, ln(:), qoff(:), ls(:, :), py(:, :), lo(:, :), &
                                   hi(:, :), key(:), zc(:)
        logical, intent(in) :: rd(:, :)
        real(wp), intent(in) :: gs(qoff(nc + 1), gr%ne, gr%ndir), zw(:)
        real(wp), intent(inout) :: kc(:, :)
        integer(ip), allocatable :: zl(:), zm(:, :), zco(:, :), zs(:, :), perm(:), zcs(:), &
                                    bca(:), bcb(:), blo(:, :), bhi(:, :)
        real(wp), allocatable :: zwt(:, :), gs1(:, :, :), gs2(:, :, :), yz(:, :, :), kt(:, :)
        integer(ip) :: nd, ne, nq, nz, nb, c, t, p, i, k, ca, cb, d1, d2, e, c1, m1, a, b, &
                       ib, iz
        real(wp) :: v1, v2
        nd = gr%ndir
        ne = gr%ne
        nq = qoff(nc + 1)
        ! the columns z: members zm (stacked index in Q, 0: none), their coefficients zco,
        ! group columns zs (index into gcols) and weights zwt; zl: T's column -> z
        allocate (zl(size(kc, 2)), zm(2, nq), zco(2, nq), zs(2, nq), zwt(2, nq), zcs(nq))
        zl = 0
        nz = 0
        do c = 1, nc
            do t = 1, ln(c)
                p = zc(py(t, c))
                i = zl(p)
                if (i == 0) then
                    nz = nz + 1
                    zl(p) = nz
                    zcs(nz) = p
                    zm(:, nz) = [qoff(c) + t, 0_ip]
                    zco(:, nz) = [c, 0_ip]
                    zs(:, nz) = [ls(t, c), 0_ip]
                    zwt(:, nz) = [zw(py(t, c)), 0.0_wp]
                else
                    zm(2, i) = qoff(c) + t
                    zco(2, i) = c
                    zs(2, i) = ls(t, c)
                    zwt(2, i) = zw(py(t, c))
                end if
            end do
        end do
        ! order: by (ca, cb), then by the first member's reading directions; the blocks
        ! of one (ca, cb) and their ranges per direction (either member read)
        allocate (perm(nz), bca(2*nc), bcb(2*nc), blo(2*nc, nd), bhi(2*nc, nd))
        k = 0
        nb = 0
        do ca = 1, nc
            do cb = 0, nc
                i = k
                do p = 0, maxval(key)
                    do iz = 1, nz
                        if (zco(1, iz) /= ca .or. zco(2, iz) /= cb) cycle
                        if (key(zs(1, iz)) /= p) cycle
                        k = k + 1
                        perm(k) = iz
                    end do
                end do
                if (k == i) cycle
                nb = nb + 1
                bca(nb) = ca
                bcb(nb) = cb
                blo(nb, :) = 1
                bhi(nb, :) = 0
                do iz = i + 1, k
                    do d2 = 1, nd
                        if (.not. (rd(zs(1, perm(iz)), d2) .or. (cb > 0 .and. &
                                   rd(max(zs(2, perm(iz)), 1_ip), d2)))) cycle
                        if (bhi(nb, d2) == 0) blo(nb, d2) = iz
                        bhi(nb, d2) = iz
                    end do
                end do
            end do
        end do
        allocate (gs1(nz, ne, nd), gs2(nz, ne, nd), yz(nz, ne, nd), kt(maxval(ln), nz))
        gs2 = 0.0_wp
        do iz = 1, nz
            i = perm(iz)
            gs1(iz, :, :) = zwt(1, i)*gs(zm(1, i), :, :)
            if (zm(2, i) > 0) gs2(iz, :, :) = zwt(2, i)*gs(zm(2, i), :, :)
        end do
        zcs(1:nz) = zcs(perm)
        do c1 = 1, nc
            m1 = ln(c1)
            if (m1 == 0) cycle
            yz = 0.0_wp
            do d1 = 1, nd
                do e = 1, ne
                    do ib = 1, nb
                        do d2 = 1, nd
                            if (bhi(ib, d2) == 0) cycle
                            v1 = gr%jac(c1 + nc*(d1 - 1), bca(ib) + nc*(d2 - 1), e)
                            v2 = 0.0_wp
                            if (bcb(ib) > 0) v2 = gr%jac(c1 + nc*(d1 - 1), bcb(ib) + &
                                                         nc*(d2 - 1), e)
                            if (v1 == 0.0_wp .and. v2 == 0.0_wp) cycle
                            a = blo(ib, d2)
                            b = bhi(ib, d2)
                            yz(a:b, e, d1) = yz(a:b, e, d1) + v1*gs1(a:b, e, d2) + &
                                             v2*gs2(a:b, e, d2)
                        end do
                    end do
                end do
            end do
            call rows_into(nq, ne, nd, nz, size(kt, 1), gs, c1, m1, lo, hi, qoff, yz, &
                           py(:, c1), zcs(1:nz), kt, kc)
        end do
    end subroutine kc_dense_pairs

    !> kc(rows, cols) += the rows S1 of coefficient c1 (m1 of them, direction d's from
    !> lo(c1, d) to hi(c1, d)) of Gd^T on Q (gs: nq stacked columns, ne elements, nd
    !> directions) times y(:, :, d)^T (ny columns), direction by direction: Gd(:, S1)^T Y;
    !> kt the work (ldk >= m1, ny). Element by element into kc: a vector subscript on both
    !> sides made a temporary each.
    subroutine rows_into(nq, ne, nd, ny, ldk, gs, c1, m1, lo, hi, qoff, y, rows, cols, kt, kc)
        integer(ip), intent(in) :: nq, ne, nd, ny, ldk
        real(wp), intent(in) :: gs(nq, ne, nd), y(ny, ne, nd)
        integer(ip), intent(in) :: c1, m1, lo(:, :), hi(:, :), qoff(:), rows(:), cols(:)
        real(wp), intent(inout) :: kt(ldk, ny), kc(:, :)
        integer(ip) :: d, a, j, k
        kt(1:m1, :) = 0.0_wp
        do d = 1, nd
            if (hi(c1, d) == 0) cycle
            a = lo(c1, d)
            call dgemm('N', 'T', hi(c1, d) - a + 1, ny, ne, 1.0_wp, gs(qoff(c1) + a, 1, d), &
                       nq, y(1, 1, d), ny, 1.0_wp, kt(a, 1), ldk)
        end do
        do j = 1, ny
            do k = 1, m1
                kc(rows(k), cols(j)) = kc(rows(k), cols(j)) + kt(k, j)
            end do
        end do
    end subroutine rows_into

    !> LU of J (jm := jcur first in Krylov mode). Systems that hold their LU
    !> (cond_lu_holds) factorise a single-precision copy into jms: half the flops of the LU
    !> and half the memory traffic of each triangular solve; it only preconditions GMRES
    !> (cond_solve) and jm keeps J for a double LU (double) if that GMRES stalls.
    subroutine cond_factor(sys, info, errmsg, double)
        type(hbm_condensed), intent(inout) :: sys
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        logical, intent(in), optional :: double
        integer(ip) :: n, linfo, stat
        real(wp) :: t0
        logical :: single
        info = FRIROM_OK
        n = sys%n
        t0 = wtime()
        if (use_krylov(sys)) sys%jm = sys%jcur
        single = holds(sys)
        if (present(double)) single = single .and. .not. double
        if (single .and. .not. allocated(sys%jms)) then
            allocate (sys%jms(n, n), stat=stat)
            if (stat /= 0) then
                call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'condensed: single LU')
                return
            end if
        end if
        if (single) then
            sys%jms = real(sys%jm, real32)
            call sgetrf(n, n, sys%jms, n, sys%ipiv, linfo)
            ! J (at the LU's frequency gj and contact state) applied matrix-free
            sys%jfree = .true.
            if (linfo == 0) call wb_build(sys)
        else
            call dgetrf(n, n, sys%jm, n, sys%ipiv, linfo)
        end if
        sys%lu_single = single
        sys%timers(T_FACT) = sys%timers(T_FACT) + wtime() - t0
        sys%timers(N_FACT) = sys%timers(N_FACT) + 1
        sys%lu_fresh = linfo == 0
        sys%lu_any = linfo == 0
        sys%gm_spent = 0.0_wp
        sys%refresh = .false.
        if (linfo > 0) then
            call set_status(info, FRIROM_ERR_SINGULAR, errmsg, 'condensed Jacobian: '// &
                            merge('sgetrf', 'dgetrf', single)//' zero pivot')
        else if (linfo < 0) then
            call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'dgetrf: illegal argument')
        end if
    end subroutine cond_factor

    module procedure cond_solve
        integer(ip) :: linfo, j, its
        real(wp) :: t0
        logical :: ok, krylov, direct_gm
        info = FRIROM_OK
        t0 = wtime()
        krylov = use_krylov(this) .and. .not. this%lu_fresh
        direct_gm = this%gm_next
        this%gm_next = .false.
        j = 1
        if (direct_gm) then
            ! every column at once (one pass over the LU per iteration for all of them)
            call gmres(this, b, its, ok, GN_TOL, max(GN_MINIT, int(gm_cost(this)/3.0_wp, ip)))
            this%gm_spent = this%gm_spent + its
            this%timers(N_KRYLOV) = this%timers(N_KRYLOV) + its
            if (.not. ok) then
                ! too slow: factorise this J, solve below
                this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
                call modal_rmat(this)
                this%jfree = .false.
                this%refresh = .true.
                call cond_jacobian(this, info, errmsg)
                if (info /= 0) return
                t0 = wtime()
            end if
        else if (krylov) then
            ok = .true.
            do j = 1, size(b, 2)
                call gmres(this, b(:, j:j), its, ok)
                this%timers(N_KRYLOV) = this%timers(N_KRYLOV) + its
                ! a preconditioner that needs many iterations is renewed at the next J
                if (its > GM_REFRESH) this%refresh = .true.
                if (ok) cycle
                ! too slow: factorise this J and solve the remaining columns directly
                this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
                call cond_factor(this, info, errmsg)
                if (info /= 0) return
                t0 = wtime()
                exit
            end do
        else
            ok = .false.
        end if
        if (ok) then
            this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
            return
        end if
        if (this%lu_single .and. .not. this%lu_fresh) then
            ! a chord step (Jacobian reused) with the LU of an older J, as a double one
            call wb_prepare(this)
            call lu_apply(this, b)
            this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
            return
        else if (this%lu_single) then
            ! the J of the LU (matrix-free) by GMRES on its single-precision LU
            call gmres(this, b(:, j:), its, ok, GM_TOL, GS_MAXIT)
            this%timers(N_KRYLOV) = this%timers(N_KRYLOV) + its
            this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
            if (ok) return
            ! J too ill-conditioned for single precision: the double LU of the J in jm
            this%timers(N_DOUBLE) = this%timers(N_DOUBLE) + 1.0_wp
            call cond_factor(this, info, errmsg, double=.true.)
            if (info /= 0) return
            t0 = wtime()
        end if
        call dgetrs('N', this%n, size(b, 2) - j + 1, this%jm, this%n, this%ipiv, b(:, j:), &
                    size(b, 1), linfo)
        this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
        if (linfo /= 0) call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'dgetrs failed')
    end procedure cond_solve

    !> GMRES iterations an LU of J is worth (direct mode, modal route) for n unknowns, nh
    !> harmonics, nnl unknowns per coefficient and nm modes: LU 2/3 n^3 flops at LU_SPEEDUP
    !> times the rate of an iteration's triangular solves (2 n^2) and matrix-free product
    !> (8 (nh+1) nnl nm: projection and back, complex).
    pure real(wp) function lu_worth(n, nh, nnl, nm)
        integer(ip), intent(in) :: n, nh, nnl, nm
        real(wp) :: rn
        rn = real(n, wp)
        lu_worth = (2.0_wp/3.0_wp*rn**3/LU_SPEEDUP)/(2.0_wp*rn**2 + 8.0_wp* &
                   real(nh + 1, wp)*real(nnl, wp)*real(nm, wp))
    end function lu_worth

    !> lu_worth of sys (modal route), kept in gm_worth.
    real(wp) function gm_cost(sys)
        type(hbm_condensed), intent(inout) :: sys
        if (sys%gm_worth <= 0.0_wp) sys%gm_worth = lu_worth(sys%n, sys%nh, sys%nnl, &
                                                           size(sys%g, 1))
        gm_cost = sys%gm_worth
    end function gm_cost

    module procedure cond_lu_holds
        hold = lu_worth(nnl*(2*nh + 1), nh, nnl, nm) >= GN_WORTH_MIN
    end procedure cond_lu_holds

    !> Whether sys keeps LUs (single precision, carried across runs): modal, direct mode,
    !> no selection, an LU worth at least GN_WORTH_MIN GMRES iterations.
    pure logical function holds(sys)
        type(hbm_condensed), intent(in) :: sys
        holds = .false.
        if (.not. sys%modal .or. use_krylov(sys) .or. allocated(sys%sel)) return
        holds = lu_worth(sys%n, sys%nh, sys%nnl, size(sys%g, 1)) >= GN_WORTH_MIN
    end function holds

    module procedure hbm_lu_import
        select type (sys => sysc)
        type is (hbm_condensed)
            if (.not. holds(sys) .or. size(state) < 2) return
            if (all(state(1) /= [1.0_wp, 2.0_wp]) .or. any(shape(lu) /= sys%n) .or. &
                size(piv) /= sys%n) return
            if (.not. allocated(sys%jm)) return
            ! state(1) = 2: a single-precision LU (exact in lu)
            sys%lu_single = state(1) == 2.0_wp
            sys%wb_ok = .false.
            if (sys%lu_single) then
                sys%jms = real(lu, real32)
            else
                sys%jm = lu
            end if
            sys%ipiv = piv
            sys%lu_any = .true.
            sys%lu_fresh = .false.
            sys%gm_spent = state(2)
        end select
    end procedure hbm_lu_import

    module procedure hbm_lu_export
        if (size(state) < 2) return
        state(1) = 0.0_wp
        select type (sys => sysc)
        type is (hbm_condensed)
            if (.not. holds(sys) .or. .not. sys%lu_any .or. .not. allocated(sys%jm)) return
            if (any(shape(lu) /= sys%n) .or. size(piv) /= sys%n) return
            if (sys%timers(N_FACT) > 0.0_wp) then
                if (sys%lu_single) then
                    lu = real(sys%jms, wp)
                else
                    lu = sys%jm
                end if
                piv = sys%ipiv
            end if
            state(1) = merge(2.0_wp, 1.0_wp, sys%lu_single)
            state(2) = sys%gm_spent
        end select
    end procedure hbm_lu_export

    !> y = J x: the assembled jcur, or matrix-free (jfree: modal route) as
    !> x + R_h G^T J_loc G x at the Jacobian's frequency, element by element and mode by
    !> mode (R_h = A diag(g) A^H never formed).
    subroutine jmul(sys, x, y)
        type(hbm_condensed), intent(in) :: sys
        real(wp), intent(in) :: x(:)
        real(wp), intent(out) :: y(:)
        real(wp), allocatable :: xv(:, :), f(:, :), y2(:, :), vr(:, :)
        complex(wp), allocatable :: fc(:), v(:, :), b1(:, :)
        integer(ip) :: n, nu, nc, h, nm
        n = sys%n
        if (.not. sys%jfree) then
            call dgemm('N', 'N', n, 1, n, 1.0_wp, sys%jcur, n, x, n, 0.0_wp, y, n)
            return
        end if
        nu = sys%nnl
        nc = sys%nc
        xv = reshape(x, [nu, nc])
        allocate (f(nu, nc), y2(nu, nc), fc(nu), v(size(sys%gj, 1), 1), b1(nu, 1))
        call kmul(sys, xv, f, .false.)
        if (allocated(sys%phr)) then
            ! real modes, the same for every harmonic: all harmonics in two products (the
            ! modes are read twice, not twice per harmonic); A^T commutes with harm_col
            nm = size(sys%gj, 1)
            allocate (vr(nm, nc))
            call dgemm('T', 'N', nm, nc, nu, 1.0_wp, sys%phr, size(sys%phr, 1), f, nu, &
                       0.0_wp, vr, nm)
            do h = 0, sys%nh
                call harm_set(vr, h, sys%gj(:, h)*harm_col(vr, h))
            end do
            call dgemm('N', 'N', nu, nc, nm, 1.0_wp, sys%phr, size(sys%phr, 1), vr, nm, &
                       0.0_wp, y2, nu)
        else
            do h = 0, sys%nh
                fc = harm_col(f, h)
                call modal_project(sys, h, fc, v(:, 1))
                v(:, 1) = sys%gj(:, h)*v(:, 1)
                call modal_apply(sys, h, 1, nu, v, b1)
                call harm_set(y2, h, b1(:, 1))
            end do
        end if
        y = x + reshape(y2, [n])
    end subroutine jmul

    !> f = K x (trans: K^T x) for K = dF_c/dU = G^T J_e G element by element, x and f
    !> (nu, nc) by harmonic coefficient.
    subroutine kmul(sys, xv, f, trans)
        type(hbm_condensed), intent(in) :: sys
        real(wp), intent(in) :: xv(:, :)
        real(wp), intent(out) :: f(:, :)
        logical, intent(in) :: trans
        real(wp), allocatable :: xl(:, :), fl(:)
        integer(ip) :: nc, g, e, d, r, k
        nc = sys%nc
        f = 0.0_wp
        do g = 1, size(sys%cs%grp)
            associate (gr => sys%cs%grp(g), gg => sys%cs%g)
                allocate (xl(nc, gr%ndir), fl(nc*gr%ndir))
                do e = 1, gr%ne
                    do d = 1, gr%ndir
                        r = gr%row0 + (e - 1)*gr%ndir + d
                        xl(:, d) = 0.0_wp
                        do k = gg%p(r), gg%p(r + 1) - 1
                            xl(:, d) = xl(:, d) + gg%x(k)*xv(gg%i(k), :)
                        end do
                    end do
                    if (trans) then
                        fl = matmul(reshape(xl, [nc*gr%ndir]), gr%jac(:, :, e))
                    else
                        fl = matmul(gr%jac(:, :, e), reshape(xl, [nc*gr%ndir]))
                    end if
                    do d = 1, gr%ndir
                        r = gr%row0 + (e - 1)*gr%ndir + d
                        do k = gg%p(r), gg%p(r + 1) - 1
                            f(gg%i(k), :) = f(gg%i(k), :) + gg%x(k)*fl(1 + nc*(d - 1):nc*d)
                        end do
                    end do
                end do
                deallocate (xl, fl)
            end associate
        end do
    end subroutine kmul

    !> The Woodbury data of a fresh single LU (real modes): the WB_PAIRS (mode, harmonic
    !> >= 1) pairs whose factor moves most with w at the LU's w (|dg| |phi|^2), their U,
    !> LU^-1 U, U^T K and its product (see hbm_condensed%wb_ok). Only a preconditioner.
    subroutine wb_build(sys)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), allocatable :: sens(:, :), nphi(:), xv(:, :), f(:, :)
        real(real32), allocatable :: ws(:, :)
        integer(ip) :: nu, nc, nm, np, k, h, r, c, q, loc(2), linfo, n, stat
        real(wp) :: smax
        sys%wb_ok = .false.
        sys%wb_at = -1.0_wp
        sys%wb_w0 = sys%wj
        ! dg is that of the receptances' w, the J's (each eval with jac precedes its solve)
        if (.not. allocated(sys%phr) .or. sys%nh < 1 .or. sys%w_cache /= sys%wj) return
        nu = sys%nnl
        nc = sys%nc
        n = sys%n
        nm = size(sys%gj, 1)
        allocate (sens(nm, sys%nh), nphi(nm))
        do r = 1, nm
            nphi(r) = sum(sys%phr(1:nu, r)**2)
        end do
        do h = 1, sys%nh
            sens(:, h) = abs(sys%dg(:, h))*sys%wj*nphi
        end do
        smax = maxval(sens)
        ! an undamped mode at resonance: no finite scale to rank the pairs by
        if (.not. (smax > 0.0_wp .and. smax <= huge(smax))) return
        np = min(WB_PAIRS, nm*sys%nh)
        if (allocated(sys%wbm)) deallocate (sys%wbm, sys%wbh, sys%wbg)
        if (allocated(sys%wbw)) deallocate (sys%wbw, sys%wbv, sys%wbs, sys%wbl, sys%wbp)
        allocate (sys%wbm(np), sys%wbh(np), sys%wbg(np), stat=stat)
        if (stat /= 0) return
        k = 0
        do while (k < np)
            loc = maxloc(sens)
            if (.not. sens(loc(1), loc(2)) > WB_FLOOR*smax) exit
            k = k + 1
            sys%wbm(k) = loc(1)
            sys%wbh(k) = loc(2)
            sys%wbg(k) = sys%gj(loc(1), loc(2))
            sens(loc(1), loc(2)) = -1.0_wp
        end do
        np = k
        if (np == 0) return
        allocate (sys%wbw(n, 2*np), sys%wbv(2*np, n), sys%wbs(2*np, 2*np), &
                  sys%wbl(2*np, 2*np), sys%wbp(2*np), xv(nu, nc), f(nu, nc), stat=stat)
        if (stat /= 0) then     ! no correction: the LU alone preconditions
            if (allocated(sys%wbw)) deallocate (sys%wbw, sys%wbv, sys%wbs, sys%wbl, sys%wbp)
            return
        end if
        sys%wbw = 0.0_wp
        do k = 1, np
            do q = 0, 1
                c = 2*sys%wbh(k) + q
                sys%wbw(nu*(c - 1) + 1:nu*c, 2*k - 1 + q) = sys%phr(1:nu, sys%wbm(k))
                ! row of V: (K^T U_k)^T
                xv = 0.0_wp
                xv(:, c) = sys%phr(1:nu, sys%wbm(k))
                call kmul(sys, xv, f, .true.)
                sys%wbv(2*k - 1 + q, :) = reshape(f, [n])
            end do
        end do
        ws = real(sys%wbw, real32)
        call sgetrs('N', n, 2*np, sys%jms, n, sys%ipiv, ws, n, linfo)
        sys%wbw = real(ws, wp)
        call dgemm('N', 'N', 2*np, 2*np, n, 1.0_wp, sys%wbv, 2*np, sys%wbw, n, 0.0_wp, &
                   sys%wbs, 2*np)
        sys%wb_ok = linfo == 0
    end subroutine wb_build

    !> The small LU of I + D wbs for the factors at the J's w (gj), D the change since the
    !> LU in the real harmonic form ([dr di; -di dr] per pair).
    subroutine wb_prepare(sys)
        type(hbm_condensed), intent(inout) :: sys
        integer(ip) :: k, m, i, linfo
        complex(wp) :: d
        real(wp) :: dr, di
        if (.not. (sys%wb_ok .and. sys%lu_single) .or. sys%wb_at == sys%wj) return
        sys%wb_at = sys%wj
        if (sys%wj == sys%wb_w0) return       ! D = 0 at the LU's own frequency
        m = size(sys%wbs, 1)
        do k = 1, m/2
            d = sys%gj(sys%wbm(k), sys%wbh(k)) - sys%wbg(k)
            dr = real(d, wp)
            di = aimag(d)
            i = 2*k - 1
            sys%wbl(i, :) = dr*sys%wbs(i, :) + di*sys%wbs(i + 1, :)
            sys%wbl(i + 1, :) = -di*sys%wbs(i, :) + dr*sys%wbs(i + 1, :)
        end do
        do i = 1, m
            sys%wbl(i, i) = sys%wbl(i, i) + 1.0_wp
        end do
        call dgetrf(m, m, sys%wbl, m, sys%wbp, linfo)
        if (linfo /= 0) sys%wb_ok = .false.
    end subroutine wb_prepare

    !> w := M^-1 w for the LU held (jms single precision, or jm), all columns at once. Its
    !> work arrays are kept on sys (lws, wbt) from call to call.
    subroutine lu_apply(sys, w)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(inout) :: w(:, :)
        real(real32), allocatable :: ws(:, :)
        real(wp), allocatable :: t(:, :)
        complex(wp) :: d
        integer(ip) :: n, linfo, m, k, nr
        n = sys%n
        nr = size(w, 2)
        if (sys%lu_single) then
            call move_alloc(sys%lws, ws)
            if (allocated(ws)) then
                if (size(ws, 1) /= n .or. size(ws, 2) < nr) deallocate (ws)
            end if
            if (.not. allocated(ws)) allocate (ws(n, nr))
            ws(:, 1:nr) = real(w, real32)
            call sgetrs('N', n, nr, sys%jms, n, sys%ipiv, ws, n, linfo)
            w = real(ws(:, 1:nr), wp)
            call move_alloc(ws, sys%lws)
            if (sys%wb_ok .and. sys%wb_at == sys%wj .and. sys%wj /= sys%wb_w0) then
                ! w -= W (I + D S)^-1 D V w; t(:, 1:nr) = V w, t(:, nr+1:) = D V w
                m = size(sys%wbs, 1)
                call move_alloc(sys%wbt, t)
                if (allocated(t)) then
                    if (size(t, 1) /= m .or. size(t, 2) < 2*nr) deallocate (t)
                end if
                if (.not. allocated(t)) allocate (t(m, 2*nr))
                call dgemm('N', 'N', m, nr, n, 1.0_wp, sys%wbv, m, w, size(w, 1), &
                           0.0_wp, t, m)
                associate (t1 => t(:, 1:nr), t2 => t(:, nr + 1:2*nr))
                    do k = 1, m/2
                        d = sys%gj(sys%wbm(k), sys%wbh(k)) - sys%wbg(k)
                        t2(2*k - 1, :) = real(d, wp)*t1(2*k - 1, :) + aimag(d)*t1(2*k, :)
                        t2(2*k, :) = -aimag(d)*t1(2*k - 1, :) + real(d, wp)*t1(2*k, :)
                    end do
                end associate
                call dgetrs('N', m, nr, sys%wbl, m, sys%wbp, t(1, nr + 1), m, linfo)
                call dgemm('N', 'N', n, nr, m, -1.0_wp, sys%wbw, n, t(1, nr + 1), m, 1.0_wp, &
                           w, size(w, 1))
                call move_alloc(t, sys%wbt)
            end if
        else
            call dgetrs('N', n, nr, sys%jm, n, sys%ipiv, w, size(w, 1), linfo)
        end if
    end subroutine lu_apply

    !> b := J^-1 b, column by column, by restarted flexible GMRES on jcur (or J matrix-free),
    !> right-preconditioned by the LU held (lu_apply, from an earlier J or in single
    !> precision: the preconditioned directions Z are kept, so x = x0 + Z y is exact for
    !> an inexact M), from x0 = M^-1 b, to a residual of GM_TOL |b| (or tol |b|). The
    !> columns iterate in lockstep: one lu_apply per iteration for all of them. its: the
    !> iterations summed over the columns; ok false (b unchanged) when a column needs
    !> more than GM_MAXIT (or maxit).
    subroutine gmres(sys, b, its, ok, tol, maxit)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(inout) :: b(:, :)
        integer(ip), intent(out) :: its
        logical, intent(out) :: ok
        real(wp), intent(in), optional :: tol
        integer(ip), intent(in), optional :: maxit
        integer(ip), parameter :: m = GM_RESTART
        real(wp), allocatable :: v(:, :, :), z(:, :, :), hh(:, :, :), cs(:, :), sn(:, :), &
                                 gv(:, :), x(:, :), r(:), w(:, :), bn(:)
        real(wp) :: beta, tmp, rtol
        integer(ip) :: n, nb, c, q, na, j, i, itmax
        integer(ip), allocatable :: itc(:), kk(:), ac(:)
        logical, allocatable :: done(:), act(:)
        logical :: slow
        n = sys%n
        nb = size(b, 2)
        rtol = GM_TOL
        if (present(tol)) rtol = tol
        itmax = GM_MAXIT
        if (present(maxit)) itmax = maxit
        ! the bases: kept on sys (gmv, gmz) from call to call, lent here
        call move_alloc(sys%gmv, v)
        call move_alloc(sys%gmz, z)
        if (allocated(v)) then
            if (size(v, 1) /= n .or. size(v, 3) < nb) deallocate (v, z)
        end if
        if (.not. allocated(v)) allocate (v(n, m + 1, nb), z(n, m, nb))
        allocate (hh(m + 1, m, nb), cs(m, nb), sn(m, nb), gv(m + 1, nb), r(n), w(n, nb), &
                  bn(nb), itc(nb), kk(nb), ac(nb), done(nb), act(nb))
        its = 0
        ok = .false.
        slow = .false.
        itc = 0
        do c = 1, nb
            bn(c) = norm2(b(:, c))
        end do
        done = bn == 0.0_wp
        call wb_prepare(sys)
        x = b
        call lu_apply(sys, x)
        restarts: do
            ! r = b - J x per open column
            act = .false.
            do c = 1, nb
                if (done(c)) cycle
                call jmul(sys, x(:, c), r)
                r = b(:, c) - r
                beta = norm2(r)
                if (beta <= rtol*bn(c)) then
                    done(c) = .true.
                    cycle
                end if
                if (itc(c) >= itmax) then
                    slow = .true.           ! too slow: b unchanged
                    exit restarts
                end if
                v(:, 1, c) = r/beta
                gv(:, c) = 0.0_wp
                gv(1, c) = beta
                act(c) = .true.
            end do
            if (all(done)) exit
            kk = 0
            do j = 1, m
                na = 0
                do c = 1, nb
                    if (.not. act(c)) cycle
                    na = na + 1
                    ac(na) = c
                    w(:, na) = v(:, j, c)
                end do
                if (na == 0) exit
                call lu_apply(sys, w(:, 1:na))
                do q = 1, na
                    c = ac(q)
                    itc(c) = itc(c) + 1
                    kk(c) = j
                    ! v_j+1 = J M^-1 v_j, orthogonalised (modified Gram-Schmidt)
                    z(:, j, c) = w(:, q)
                    call jmul(sys, z(:, j, c), v(:, j + 1, c))
                    do i = 1, j
                        hh(i, j, c) = dot_product(v(:, i, c), v(:, j + 1, c))
                        v(:, j + 1, c) = v(:, j + 1, c) - hh(i, j, c)*v(:, i, c)
                    end do
                    hh(j + 1, j, c) = norm2(v(:, j + 1, c))
                    if (hh(j + 1, j, c) > 0.0_wp) v(:, j + 1, c) = v(:, j + 1, c)/hh(j + 1, j, c)
                    do i = 1, j - 1
                        tmp = cs(i, c)*hh(i, j, c) + sn(i, c)*hh(i + 1, j, c)
                        hh(i + 1, j, c) = -sn(i, c)*hh(i, j, c) + cs(i, c)*hh(i + 1, j, c)
                        hh(i, j, c) = tmp
                    end do
                    tmp = hypot(hh(j, j, c), hh(j + 1, j, c))
                    if (tmp == 0.0_wp) then
                        ! breakdown: column j adds nothing; solve with the first j - 1
                        kk(c) = j - 1
                        act(c) = .false.
                        cycle
                    end if
                    cs(j, c) = hh(j, j, c)/tmp
                    sn(j, c) = hh(j + 1, j, c)/tmp
                    hh(j, j, c) = tmp
                    hh(j + 1, j, c) = 0.0_wp
                    gv(j + 1, c) = -sn(j, c)*gv(j, c)
                    gv(j, c) = cs(j, c)*gv(j, c)
                    if (abs(gv(j + 1, c)) <= 0.1_wp*rtol*bn(c) .or. itc(c) >= itmax) &
                        act(c) = .false.
                end do
            end do
            ! x += Z y, H y = g (upper triangular)
            do c = 1, nb
                if (done(c) .or. kk(c) == 0) cycle
                do i = kk(c), 1, -1
                    gv(i, c) = (gv(i, c) - dot_product(hh(i, i + 1:kk(c), c), &
                                                       gv(i + 1:kk(c), c)))/hh(i, i, c)
                end do
                call dgemv('N', n, kk(c), 1.0_wp, z(:, :, c), n, gv(:, c), 1, 1.0_wp, &
                           x(:, c), 1)
            end do
        end do restarts
        its = sum(itc)
        call move_alloc(v, sys%gmv)
        call move_alloc(z, sys%gmz)
        if (slow) return
        b = x
        ok = .true.
    end subroutine gmres

    !> xe_leak at the receptances' frequency and load factor s: |T X_e off the selection|
    !> / |on it|, T X_e the loads' linear response at the coordinates (every row; the
    !> residual keeps only the kept ones).
    subroutine load_leak(sys, s)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(in) :: s
        complex(wp), allocatable :: x1(:, :), b1(:, :), xe(:)
        real(wp), allocatable :: xr(:, :), br(:, :)
        real(wp) :: on, off
        integer(ip) :: h, nm, nu
        on = 0.0_wp
        off = 0.0_wp
        nu = sys%nnl
        allocate (xe(nu))
        if (allocated(sys%phr)) then
            ! every harmonic in one product (phr is the same for all)
            nm = size(sys%phr, 2)
            allocate (xr(nm, 2*(sys%nh + 1)), br(nu, 2*(sys%nh + 1)))
            do h = 0, sys%nh
                xr(:, 2*h + 1) = real(sys%g(:, h)*(sys%qf(:, h) + s*sys%qf1(:, h)), wp)
                xr(:, 2*h + 2) = aimag(sys%g(:, h)*(sys%qf(:, h) + s*sys%qf1(:, h)))
            end do
            call dgemm('N', 'N', nu, 2*(sys%nh + 1), nm, 1.0_wp, sys%phr, size(sys%phr, 1), &
                       xr, nm, 0.0_wp, br, nu)
        else if (sys%modal) then
            allocate (x1(size(sys%g, 1), 1), b1(nu, 1))
        end if
        do h = 0, sys%nh
            if (allocated(sys%phr)) then
                xe = cmplx(br(:, 2*h + 1), br(:, 2*h + 2), wp)
            else if (sys%modal) then
                x1(:, 1) = sys%g(:, h)*(sys%qf(:, h) + s*sys%qf1(:, h))
                call modal_apply(sys, h, 1, nu, x1, b1)
                xe = b1(:, 1)
            else
                xe = sys%tye0(:, h) + s*sys%tye1(:, h)
            end if
            on = on + sum(abs(xe)**2, mask=sys%kmask(:, h))
            off = off + sum(abs(xe)**2, mask=.not. sys%kmask(:, h))
            ! harm_col: cosine real(xe), sine -aimag(xe)
            if (allocated(sys%tk) .and. h > 0) off = off + pair_off(sys, h, real(xe, wp), &
                                                                     -aimag(xe))
        end do
        sys%xe_leak = ratio(off, on)
    end subroutine load_leak

    !> orb_leak at y, after a contact_eval of every element there (sys%fd): |T^T fd - the
    !> orbits' forces| / |the orbits' forces|, what Newton's evaluations left out.
    subroutine orbit_leak(sys, y, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(in) :: y(:)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp), allocatable :: fz(:), fa(:)
        allocate (fz(sys%n), fa(sys%n))
        call orbit_forces(sys, y, .false., fz, info, errmsg)
        if (info /= 0) return
        call hbm_sel_reduce(sys, reshape(sys%fd, [size(sys%fd)]), fa)
        sys%orb_leak = ratio(sum((fa - fz)**2), sum(fz**2))
    end subroutine orbit_leak

    !> Whether a selected system's contact forces (sys%fd, real modes) off the kept rows
    !> are below OUT_SKIP of those on them, so that the outputs may leave them out: their
    !> response is at most that fraction times the amplification of a mode off the
    !> selection over one on it (1 / (2 zeta): 250 for the flange's 0.2 %), ~1e-10 of the
    !> outputs, below Newton's tolerance. Refreshes the kept mode rows (sel_rows).
    logical function sel_only(sys)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), parameter :: OUT_SKIP = 1.0e-12_wp
        real(wp) :: on, off
        sel_only = .false.
        if (.not. allocated(sys%sel)) return
        call fd_split(sys, on, off)
        sel_only = off <= OUT_SKIP**2*on
        if (sel_only) call sel_rows(sys)
    end function sel_only

    module procedure cond_outputs
        real(wp) :: w, s
        integer(ip) :: h, j, o, nu, nout, nm
        complex(wp), allocatable :: fc(:), z(:), v(:), x1(:, :), b1(:, :)
        real(wp), allocatable :: fr(:, :), vr(:, :)
        info = FRIROM_OK
        call freq_load(this, lam, w, s)
        if (w /= this%w_cache) then
            call cond_receptance(this, w, info, errmsg)
            if (info /= 0) return
        end if
        call hbm_contact_forces(this, y, .false., info, errmsg)
        if (info /= 0) return
        nu = this%nnl
        nout = size(this%outdofs)
        if (allocated(this%sel)) call load_leak(this, s)
        if (this%orbits) then
            call orbit_leak(this, y, info, errmsg)
            if (info /= 0) return
        end if
        allocate (fc(nu), z(nout))
        if (this%modal) then
            nm = size(this%g, 1)
            allocate (v(nm), x1(nm, 1), b1(nout, 1))
        end if
        if (allocated(this%phr) .and. sel_only(this)) then
            ! the forces off the selection negligible: A^T fc over the kept rows
            allocate (vr(nm, 2*(this%nh + 1)))
            do h = 0, this%nh
                fc = harm_col(this%fd, h)
                call project_kept(this, h, fc, v)
                vr(:, 2*h + 1) = real(v, wp)
                vr(:, 2*h + 2) = aimag(v)
            end do
        else if (allocated(this%phr)) then
            ! A^T fc of every harmonic in one product (phr is the same for all)
            allocate (fr(nu, 2*(this%nh + 1)), vr(nm, 2*(this%nh + 1)))
            do h = 0, this%nh
                fc = harm_col(this%fd, h)
                fr(:, 2*h + 1) = real(fc, wp)
                fr(:, 2*h + 2) = aimag(fc)
            end do
            call dgemm('T', 'N', nm, 2*(this%nh + 1), nu, 1.0_wp, this%phr, &
                       size(this%phr, 1), fr, nu, 0.0_wp, vr, nm)
        end if
        do h = 0, this%nh
            fc = harm_col(this%fd, h)
            if (this%modal) then
                ! x_o = Phi_o g (q - A^H fc)
                if (allocated(this%phr)) then
                    v = cmplx(vr(:, 2*h + 1), vr(:, 2*h + 2), wp)
                else
                    call modal_project(this, h, fc, v)
                end if
                x1(:, 1) = this%g(:, h)*(this%qf(:, h) + s*this%qf1(:, h) - v)
                call modal_apply(this, h, nu + 1, nu + nout, x1, b1)
                z = b1(:, 1)
            else
                do j = 1, nout
                    o = this%outdofs(j)
                    z(j) = this%ye0(o, h) + s*this%ye1(o, h) - sum(this%ymat(o, :, h)*fc)
                end do
            end if
            call harm_set(xo, h, z)
        end do
    end procedure cond_outputs
end submodule frirom_hbm_condensed
