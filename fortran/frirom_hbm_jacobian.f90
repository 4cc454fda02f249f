!> The Jacobian J = I + R_h dF_c/dU of a condensed system in real harmonic form: element
!> by element (or through a dense dF_c/dU when the elements read most coordinates), and
!> on a selection's kept unknowns (its pairs: J_z = T^T J T) from each contact group's
!> dense rows; then the LU (cond_factor).
submodule (frirom_hbm:frirom_hbm_condensed) frirom_hbm_jacobian
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_ALLOC, set_status
    implicit none

    !> A contact group's kept columns Q (kc_dense_sel): the kept (column, coefficient)
    !> pairs it reads, coefficient by coefficient, stacked.
    type :: kept_cols
        integer(ip) :: nq = 0                    !! Q's columns, every coefficient
        integer(ip), allocatable :: ln(:)        !! (nc) how many at coefficient c
        integer(ip), allocatable :: qoff(:)      !! (nc+1) Q's columns before coefficient c
        !> (ns, nc) coefficient c's (1:ln(c)), in the order of key: the group's columns
        !> (index into gcols) and their indices in y
        integer(ip), allocatable :: ls(:, :), py(:, :)
        !> (nc, nd) lo(c, d):hi(c, d): those direction d reads (one range; hi = 0: none)
        integer(ip), allocatable :: lo(:, :), hi(:, :)
        integer(ip), allocatable :: key(:)       !! (ns) order of a column: who reads it
        logical, allocatable :: rd(:, :)         !! (ns, nd) direction d's rows read s
        real(wp), allocatable :: gs(:, :, :)     !! (nq, ne, nd) Gd^T on Q, by direction
    end type kept_cols

    !> Blocks of Q's columns (stacked, as in kept_cols) that read the same coefficients of
    !> J_loc: ca(ib) and cb(ib) (0: none), and direction d's range lo(ib, d):hi(ib, d)
    !> (hi = 0: none) of block ib.
    type :: col_blocks
        integer(ip) :: n = 0
        integer(ip), allocatable :: ca(:), cb(:), lo(:, :), hi(:, :)
    end type col_blocks

contains

    module procedure cond_jacobian
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
    end procedure cond_jacobian

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

    module procedure cond_jacobian_sel
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
    end procedure cond_jacobian_sel

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
        type(kept_cols) :: kq
        integer(ip), allocatable :: ord(:), pq(:)
        real(wp), allocatable :: yt(:, :, :), kt(:, :)
        !> two directions, by the mask of those that read a column: d1 only, both, d2 only,
        !> none (each direction's columns are then one range)
        integer(ip), parameter :: ORDER2(0:3) = [3, 0, 2, 1]
        type(col_blocks) :: bl
        integer(ip) :: ns, nd, ne, nrg, c, c1, d1, s, p, k
        nd = gr%ndir
        ne = gr%ne
        nrg = ne*nd
        ns = size(gr%gcols)
        ! rd(s, d): direction d's rows read column s; key: the order of the columns within
        ! a coefficient (more than two directions: a range may hold columns it does not read)
        allocate (kq%rd(ns, nd), kq%key(ns), ord(ns))
        do d1 = 1, nd
            kq%rd(:, d1) = any(gr%gt(:, d1:nrg:nd) /= 0.0_wp, dim=2)
        end do
        do s = 1, ns
            kq%key(s) = sum([(merge(2**(d1 - 1), 0, kq%rd(s, d1)), d1=1, nd)])
            if (nd == 2) kq%key(s) = ORDER2(kq%key(s))
        end do
        k = 0
        do p = 0, maxval(kq%key)
            do s = 1, ns
                if (kq%key(s) /= p) cycle
                k = k + 1
                ord(k) = s
            end do
        end do
        ! ls(:, c): the group's columns (index into gcols) kept at coefficient c in that
        ! order, py their indices in y, lo:hi(c, d) those direction d reads
        allocate (kq%ls(ns, nc), kq%py(ns, nc), kq%ln(nc), kq%qoff(nc + 1), kq%lo(nc, nd), &
                  kq%hi(nc, nd))
        kq%qoff(1) = 0
        do c = 1, nc
            kq%ln(c) = 0
            kq%lo(c, :) = 1
            kq%hi(c, :) = 0
            do k = 1, ns
                s = ord(k)
                p = at(gr%gcols(s) + nu*(c - 1))
                if (p == 0) cycle
                kq%ln(c) = kq%ln(c) + 1
                kq%ls(kq%ln(c), c) = s
                kq%py(kq%ln(c), c) = p
                do d1 = 1, nd
                    if (.not. kq%rd(s, d1)) cycle
                    if (kq%hi(c, d1) == 0) kq%lo(c, d1) = kq%ln(c)
                    kq%hi(c, d1) = kq%ln(c)
                end do
            end do
            kq%qoff(c + 1) = kq%qoff(c) + kq%ln(c)
        end do
        kq%nq = kq%qoff(nc + 1)
        if (kq%nq == 0) return
        ! gs(q, e, d): Gd^T on Q (the kept columns of every coefficient stacked), by direction
        allocate (kq%gs(kq%nq, ne, nd))
        do d1 = 1, nd
            do c = 1, nc
                kq%gs(kq%qoff(c) + 1:kq%qoff(c + 1), :, d1) = &
                    gr%gt(kq%ls(1:kq%ln(c), c), d1:nrg:nd)
            end do
        end do
        if (present(zc)) then
            call kc_dense_pairs(gr, kq, zc, zw, kc)
            return
        end if
        allocate (yt(kq%nq, ne, nd), kt(maxval(kq%ln), kq%nq), pq(kq%nq))
        do c = 1, nc
            pq(kq%qoff(c) + 1:kq%qoff(c + 1)) = kq%py(1:kq%ln(c), c)
        end do
        ! a block per coefficient, its columns' ranges by direction
        bl%n = nc
        bl%ca = [(c, c=1, nc)]
        bl%cb = spread(0_ip, 1, nc)
        bl%lo = spread(kq%qoff(1:nc), 2, nd) + kq%lo
        bl%hi = merge(spread(kq%qoff(1:nc), 2, nd) + kq%hi, 0_ip, kq%hi > 0)
        do c1 = 1, nc
            if (kq%ln(c1) == 0) cycle
            call jloc_gd(gr, nc, c1, bl, kq%gs, kq%gs, yt)
            call rows_into(kq, c1, yt, pq, kt, kc)
        end do
    end subroutine kc_dense_sel

    !> y(:, :, d1) = J_loc Gd on the blocks' columns for coefficient c1's rows (directions
    !> d1): block ib adds J_loc(c1 d1, ca d2) g1(lo:hi, :, d2) and, where cb > 0,
    !> J_loc(c1 d1, cb d2) g2(lo:hi, :, d2), element by element, for each direction d2
    !> that reads it. nc: J_loc's coefficients.
    subroutine jloc_gd(gr, nc, c1, bl, g1, g2, y)
        type(contact_group), intent(in) :: gr
        integer(ip), intent(in) :: nc, c1
        type(col_blocks), intent(in) :: bl
        real(wp), intent(in) :: g1(:, :, :), g2(:, :, :)   !! (columns, ne, nd)
        real(wp), intent(out) :: y(:, :, :)                !! (columns, ne, nd)
        integer(ip) :: d1, d2, e, ib, a, b
        real(wp) :: v1, v2
        y = 0.0_wp
        do d1 = 1, gr%ndir
            do e = 1, gr%ne
                do ib = 1, bl%n
                    do d2 = 1, gr%ndir
                        if (bl%hi(ib, d2) == 0) cycle
                        v1 = gr%jac(c1 + nc*(d1 - 1), bl%ca(ib) + nc*(d2 - 1), e)
                        v2 = 0.0_wp
                        if (bl%cb(ib) > 0) v2 = gr%jac(c1 + nc*(d1 - 1), bl%cb(ib) + &
                                                       nc*(d2 - 1), e)
                        if (v1 == 0.0_wp .and. v2 == 0.0_wp) cycle
                        a = bl%lo(ib, d2)
                        b = bl%hi(ib, d2)
                        if (bl%cb(ib) > 0) then
                            y(a:b, e, d1) = y(a:b, e, d1) + v1*g1(a:b, e, d2) + &
                                            v2*g2(a:b, e, d2)
                        else
                            y(a:b, e, d1) = y(a:b, e, d1) + v1*g1(a:b, e, d2)
                        end if
                    end do
                end do
            end do
        end do
    end subroutine jloc_gd

    !> kc_dense_sel for a selection's pairs: kc(S1 c1, z) += Gd(:, S1)^T Y_z, Y_z = J_loc
    !> Gd T on T's columns z that touch the group (one or two members in Q, a pair's in
    !> coefficients c and c + 1), the products then on half the columns. The z are grouped
    !> by their members' coefficients (ca, cb), so that J_loc's two entries are the same
    !> for a group, and ordered within it by the directions that read them: Y_z is formed
    !> from gs1 = zw Gd^T on the first members and gs2 on the second, range by range.
    subroutine kc_dense_pairs(gr, kq, zc, zw, kc)
        type(contact_group), intent(in) :: gr
        type(kept_cols), intent(in) :: kq        !! the group's kept columns (kc_dense_sel)
        integer(ip), intent(in) :: zc(:)         !! (kept) T's column of each kept unknown
        real(wp), intent(in) :: zw(:)            !! (kept) its weight there
        real(wp), intent(inout) :: kc(:, :)
        integer(ip), allocatable :: zl(:), zm(:, :), zco(:, :), zs(:, :), perm(:), zcs(:)
        real(wp), allocatable :: zwt(:, :), gs1(:, :, :), gs2(:, :, :), yz(:, :, :), kt(:, :)
        type(col_blocks) :: bl
        integer(ip) :: nc, nd, ne, nq, nz, c, t, p, i, k, ca, cb, d2, c1, iz
        nc = size(kq%ln)
        nd = gr%ndir
        ne = gr%ne
        nq = kq%nq
        ! the columns z: members zm (stacked index in Q, 0: none), their coefficients zco,
        ! group columns zs (index into gcols) and weights zwt; zl: T's column -> z
        allocate (zl(size(kc, 2)), zm(2, nq), zco(2, nq), zs(2, nq), zwt(2, nq), zcs(nq))
        zl = 0
        nz = 0
        do c = 1, nc
            do t = 1, kq%ln(c)
                p = zc(kq%py(t, c))
                i = zl(p)
                if (i == 0) then
                    nz = nz + 1
                    zl(p) = nz
                    zcs(nz) = p
                    zm(:, nz) = [kq%qoff(c) + t, 0_ip]
                    zco(:, nz) = [c, 0_ip]
                    zs(:, nz) = [kq%ls(t, c), 0_ip]
                    zwt(:, nz) = [zw(kq%py(t, c)), 0.0_wp]
                else
                    zm(2, i) = kq%qoff(c) + t
                    zco(2, i) = c
                    zs(2, i) = kq%ls(t, c)
                    zwt(2, i) = zw(kq%py(t, c))
                end if
            end do
        end do
        ! order: by (ca, cb), then by the first member's reading directions; the blocks
        ! of one (ca, cb) and their ranges per direction (either member read)
        allocate (perm(nz), bl%ca(2*nc), bl%cb(2*nc), bl%lo(2*nc, nd), bl%hi(2*nc, nd))
        k = 0
        bl%n = 0
        do ca = 1, nc
            do cb = 0, nc
                i = k
                do p = 0, maxval(kq%key)
                    do iz = 1, nz
                        if (zco(1, iz) /= ca .or. zco(2, iz) /= cb) cycle
                        if (kq%key(zs(1, iz)) /= p) cycle
                        k = k + 1
                        perm(k) = iz
                    end do
                end do
                if (k == i) cycle
                bl%n = bl%n + 1
                bl%ca(bl%n) = ca
                bl%cb(bl%n) = cb
                bl%lo(bl%n, :) = 1
                bl%hi(bl%n, :) = 0
                do iz = i + 1, k
                    do d2 = 1, nd
                        if (.not. (kq%rd(zs(1, perm(iz)), d2) .or. (cb > 0 .and. &
                                   kq%rd(max(zs(2, perm(iz)), 1_ip), d2)))) cycle
                        if (bl%hi(bl%n, d2) == 0) bl%lo(bl%n, d2) = iz
                        bl%hi(bl%n, d2) = iz
                    end do
                end do
            end do
        end do
        allocate (gs1(nz, ne, nd), gs2(nz, ne, nd), yz(nz, ne, nd), kt(maxval(kq%ln), nz))
        gs2 = 0.0_wp
        do iz = 1, nz
            i = perm(iz)
            gs1(iz, :, :) = zwt(1, i)*kq%gs(zm(1, i), :, :)
            if (zm(2, i) > 0) gs2(iz, :, :) = zwt(2, i)*kq%gs(zm(2, i), :, :)
        end do
        zcs(1:nz) = zcs(perm)
        do c1 = 1, nc
            if (kq%ln(c1) == 0) cycle
            call jloc_gd(gr, nc, c1, bl, gs1, gs2, yz)
            call rows_into(kq, c1, yz, zcs(1:nz), kt, kc)
        end do
    end subroutine kc_dense_pairs

    !> kc(rows, cols) += the rows S1 of coefficient c1 (kq%ln(c1) of them, direction d's
    !> from lo(c1, d) to hi(c1, d), in y at kq%py(:, c1)) of Gd^T on Q (kq%gs) times
    !> y(:, :, d)^T, direction by direction: Gd(:, S1)^T Y; kt the work. Element by
    !> element into kc: a vector subscript on both sides made a temporary each.
    subroutine rows_into(kq, c1, y, cols, kt, kc)
        type(kept_cols), intent(in) :: kq
        integer(ip), intent(in) :: c1
        integer(ip), intent(in) :: cols(:)                !! (ny) kc's column of each of y's
        real(wp), intent(in) :: y(size(cols), size(kq%gs, 2), size(kq%gs, 3))
        real(wp), intent(inout) :: kt(maxval(kq%ln), size(cols))  !! work
        real(wp), intent(inout) :: kc(:, :)
        integer(ip) :: d, a, j, k, ny, m1
        ny = size(y, 1)
        m1 = kq%ln(c1)
        kt(1:m1, :) = 0.0_wp
        do d = 1, size(y, 3)
            if (kq%hi(c1, d) == 0) cycle
            a = kq%lo(c1, d)
            call dgemm('N', 'T', kq%hi(c1, d) - a + 1, ny, size(y, 2), 1.0_wp, &
                       kq%gs(kq%qoff(c1) + a, 1, d), kq%nq, y(1, 1, d), ny, 1.0_wp, kt(a, 1), &
                       size(kt, 1))
        end do
        do j = 1, ny
            do k = 1, m1
                kc(kq%py(k, c1), cols(j)) = kc(kq%py(k, c1), cols(j)) + kt(k, j)
            end do
        end do
    end subroutine rows_into
end submodule frirom_hbm_jacobian
