!> The contact set of frirom_hbm: G x, the AFT of every contact group,
!> G^T f and G^T J G, and the sliders a converged point hands on.
submodule (frirom_hbm) frirom_hbm_contacts
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_PARAM, FRIROM_ERR_MODEL, &
                             set_status
    use frirom_banded, only: band_add
    use frirom_aft, only: aft_eval, law_nslider
    use frirom_user_law, only: user_aft
    implicit none

contains

    module procedure contact_eval
        integer(ip) :: g, e, d, row, k, c, nc, nrg, ns
        real(wp) :: acc
        real(wp), allocatable :: wnew(:, :), fkeep(:, :, :)
        logical :: upd, ok
        info = FRIROM_OK
        ok = .true.
        upd = .false.
        if (present(carry)) upd = carry
        nc = cs%nc
        fd = 0.0_wp
        cs%settled = .true.
        if (present(keep)) then
            if (size(keep, 1) /= size(xd, 1) .or. 2*size(keep, 2) - 1 /= nc) then
                call set_status(info, FRIROM_ERR_SIZE, errmsg, 'contact_eval: keep must be '// &
                                '(columns, H+1)')
                return
            end if
        end if
        do g = 1, size(cs%grp)
            associate (gr => cs%grp(g), gg => cs%g)
                if (gr%gx_mode == 0) call choose_gx(gr, gg, nc)
                nrg = gr%ne*gr%ndir
                if (gr%gx_mode == 3) then
                    if (present(keep)) then
                        call gx_dir_kept(gr, xd, keep)
                    else
                        call gx_dir(gr, xd)
                    end if
                else if (gr%gx_mode == 2) then
                    ! x(c, r) = sum_s xd(col_s, c) G(r, col_s): one product
                    ns = size(gr%gcols)
                    do c = 1, nc
                        gr%gxs(:, c) = xd(gr%gcols, c)
                    end do
                    call dgemm('T', 'N', nc, nrg, ns, 1.0_wp, gr%gxs, ns, gr%gt, ns, 0.0_wp, &
                               gr%x, nc)
                else
                    do e = 1, gr%ne
                        do d = 1, gr%ndir
                            row = gr%row0 + (e - 1)*gr%ndir + d
                            do c = 1, nc        ! one accumulator per coefficient
                                acc = 0.0_wp
                                do k = gg%p(row), gg%p(row + 1) - 1
                                    acc = acc + gg%x(k)*xd(gg%i(k), c)
                                end do
                                gr%x(c, d, e) = acc
                            end do
                        end do
                    end do
                end if
                if (.not. allocated(gr%held)) allocate (gr%held(gr%ne), source=0_ip)
                if (gr%law < 0) then            ! a user law: through the run's callback
                    gr%states = 0.0_wp
                    if (upd) then
                        wnew = gr%w0
                        call user_aft(cs%ulaw, g, plan%fp%nsamp, law_nslider(gr%law), gr%x, &
                                      gr%params, gr%w0, gr%f, info, errmsg, slider=wnew)
                        if (info == 0) gr%w0 = wnew
                        deallocate (wnew)
                    else if (jac) then
                        call user_aft(cs%ulaw, g, plan%fp%nsamp, law_nslider(gr%law), gr%x, &
                                      gr%params, gr%w0, gr%f, info, errmsg, jac=gr%jac)
                    else
                        call user_aft(cs%ulaw, g, plan%fp%nsamp, law_nslider(gr%law), gr%x, &
                                      gr%params, gr%w0, gr%f, info, errmsg)
                    end if
                else if (upd) then
                    allocate (wnew, mold=gr%w0)
                    wnew = gr%w0
                    call aft_eval(plan, gr%law, gr%x, gr%params, gr%w0, gr%f, info, errmsg, &
                                  states=gr%states, slider=wnew, relative=.true., &
                                  held=gr%held, settled=ok)
                    if (info == 0) gr%w0 = wnew
                    deallocate (wnew)
                else if (jac) then
                    call aft_eval(plan, gr%law, gr%x, gr%params, gr%w0, gr%f, info, errmsg, &
                                  jac=gr%jac, states=gr%states, relative=.true., held=gr%held, &
                                  settled=ok)
                else
                    call aft_eval(plan, gr%law, gr%x, gr%params, gr%w0, gr%f, info, errmsg, &
                                  states=gr%states, relative=.true., held=gr%held, settled=ok)
                end if
                if (gr%law > 0) cs%settled = cs%settled .and. ok
                if (info /= 0) return
                if (allocated(gr%ks)) then        ! free bodies: f - Ks x, restored below
                    fkeep = gr%f
                    if (jac .and. .not. upd) then
                        call free_subtract(gr%ks, gr%kp, gr%x, gr%f, gr%jac)
                    else
                        call free_subtract(gr%ks, gr%kp, gr%x, gr%f)
                    end if
                end if
                if (gr%gx_mode == 3) then
                    call gtf_dir(gr, fd)
                else if (gr%gx_mode == 2) then
                    ! fd(col_s, c) += sum_r G(r, col_s) f(c, r)
                    call dgemm('N', 'T', ns, nc, nrg, 1.0_wp, gr%gt, ns, gr%f, nc, 0.0_wp, &
                               gr%gxs, ns)
                    do c = 1, nc
                        fd(gr%gcols, c) = fd(gr%gcols, c) + gr%gxs(:, c)
                    end do
                else
                    do e = 1, gr%ne
                        do d = 1, gr%ndir
                            row = gr%row0 + (e - 1)*gr%ndir + d
                            do k = gg%p(row), gg%p(row + 1) - 1
                                fd(gg%i(k), :) = fd(gg%i(k), :) + gg%x(k)*gr%f(:, d, e)
                            end do
                        end do
                    end do
                end if
                if (allocated(gr%ks)) call move_alloc(fkeep, gr%f)
            end associate
        end do
    end procedure contact_eval

    !> gx_mode 3: x(:, d, :) = G_d xd by one product per direction d over the columns its
    !> rows read (gr%dcols, gr%gdt).
    subroutine gx_dir(gr, xd)
        type(contact_group), intent(inout) :: gr
        real(wp), intent(in) :: xd(:, :)           !! (ncol, nc)
        integer(ip) :: d, k1, m, nc
        nc = size(xd, 2)
        do d = 1, gr%ndir
            k1 = gr%dptr(d)
            m = gr%dptr(d + 1) - k1
            if (m == 0) then
                gr%x(:, d, :) = 0.0_wp
                cycle
            end if
            gr%gxs(1:m, :) = xd(gr%dcols(k1:k1 + m - 1), :)
            call dgemm('T', 'N', nc, gr%ne, m, 1.0_wp, gr%gxs, size(gr%gxs, 1), &
                       gr%gdt(k1, 1), size(gr%gdt, 1), 0.0_wp, gr%x(1, d, 1), nc*gr%ndir)
        end do
    end subroutine gx_dir

    !> gx_dir for an xd that is zero off keep (a selection): per harmonic and direction
    !> only the kept columns (the terms left out are exact zeros: the same x to rounding).
    subroutine gx_dir_kept(gr, xd, keep)
        type(contact_group), intent(inout) :: gr
        real(wp), intent(in) :: xd(:, :)           !! (ncol, nc)
        logical, intent(in) :: keep(:, 0:)         !! (ncol, 0:H)
        integer(ip) :: h, d, b, k1, m, c0, nch, nd
        logical :: same
        nd = gr%ndir
        same = allocated(gr%ksel)
        if (same) same = all(shape(gr%ksel) == shape(keep))
        if (same) same = all(gr%ksel .eqv. keep)
        if (.not. same) call kept_plan(gr, keep)
        do h = 0, size(keep, 2) - 1
            c0 = max(1, 2*h)
            nch = merge(1, 2, h == 0)
            do d = 1, nd
                b = d + nd*h
                k1 = gr%kptr(b)
                m = gr%kptr(b + 1) - k1
                if (m == 0) then
                    gr%x(c0:c0 + nch - 1, d, :) = 0.0_wp
                    cycle
                end if
                gr%gxs(1:m, 1:nch) = xd(gr%kcols(k1:k1 + m - 1), c0:c0 + nch - 1)
                call dgemm('T', 'N', nch, gr%ne, m, 1.0_wp, gr%gxs, size(gr%gxs, 1), &
                           gr%gkt(k1, 1), size(gr%gkt, 1), 0.0_wp, gr%x(c0, d, 1), &
                           size(gr%x, 1)*nd)
            end do
        end do
    end subroutine gx_dir_kept

    !> gx_mode 3: fd += G^T f by one product per direction (every column: fd off a
    !> selection is what cond_leak measures).
    subroutine gtf_dir(gr, fd)
        type(contact_group), intent(inout) :: gr
        real(wp), intent(inout) :: fd(:, :)        !! (ncol, nc)
        integer(ip) :: d, k1, m, nc, c
        nc = size(fd, 2)
        do d = 1, gr%ndir
            k1 = gr%dptr(d)
            m = gr%dptr(d + 1) - k1
            if (m == 0) cycle
            call dgemm('N', 'T', m, nc, gr%ne, 1.0_wp, gr%gdt(k1, 1), size(gr%gdt, 1), &
                       gr%f(1, d, 1), nc*gr%ndir, 0.0_wp, gr%gxs, size(gr%gxs, 1))
            do c = 1, nc        ! a direction's columns are distinct
                fd(gr%dcols(k1:k1 + m - 1), c) = fd(gr%dcols(k1:k1 + m - 1), c) + &
                                                 gr%gxs(1:m, c)
            end do
        end do
    end subroutine gtf_dir

    !> gr%kcols / kptr / gkt: gx_mode 3's columns and rows restricted, per harmonic h and
    !> direction d, to the columns kept at h (keep), and gr%ksel = keep.
    subroutine kept_plan(gr, keep)
        type(contact_group), intent(inout) :: gr
        logical, intent(in) :: keep(:, 0:)
        integer(ip) :: h, d, k, n, nd
        nd = gr%ndir
        if (allocated(gr%kcols)) deallocate (gr%kcols, gr%kptr, gr%gkt)
        n = 0
        do h = 0, size(keep, 2) - 1
            do d = 1, nd
                n = n + count(keep(gr%dcols(gr%dptr(d):gr%dptr(d + 1) - 1), h))
            end do
        end do
        allocate (gr%kcols(n), gr%kptr(nd*size(keep, 2) + 1), gr%gkt(max(n, 1), gr%ne))
        n = 0
        gr%kptr(1) = 1
        do h = 0, size(keep, 2) - 1
            do d = 1, nd
                do k = gr%dptr(d), gr%dptr(d + 1) - 1
                    if (.not. keep(gr%dcols(k), h)) cycle
                    n = n + 1
                    gr%kcols(n) = gr%dcols(k)
                    gr%gkt(n, :) = gr%gdt(k, :)
                end do
                gr%kptr(d + nd*h + 1) = n + 1
            end do
        end do
        gr%ksel = keep
    end subroutine kept_plan

    module procedure contact_assemble
        integer(ip) :: g, e, d1, d2, r1, r2, k1, k2, c1, c2, ncol, nc, i1, i2, m1, m2
        real(wp) :: v
        logical :: ok, done
        info = FRIROM_OK
        ok = .true.
        nc = cs%nc
        ncol = cs%g%ncol
        if (present(ldc)) ncol = ldc
        do g = 1, size(cs%grp)
            done = .false.
            if (present(loops)) done = loops
            if (present(kd) .and. .not. done) then
                call assemble_dense(cs%grp(g), cs%g, nc, ncol, kd, info, errmsg, done, colmap)
                if (info /= 0) return
                if (done) cycle
            end if
            associate (gr => cs%grp(g), gg => cs%g)
                do e = 1, gr%ne
                    do d1 = 1, gr%ndir
                        r1 = gr%row0 + (e - 1)*gr%ndir + d1
                        do d2 = 1, gr%ndir
                            r2 = gr%row0 + (e - 1)*gr%ndir + d2
                            do k1 = gg%p(r1), gg%p(r1 + 1) - 1
                                do k2 = gg%p(r2), gg%p(r2 + 1) - 1
                                    v = gg%x(k1)*gg%x(k2)
                                    m1 = gg%i(k1)
                                    m2 = gg%i(k2)
                                    if (present(colmap)) then
                                        m1 = colmap(m1)
                                        m2 = colmap(m2)
                                    end if
                                    do c2 = 1, nc
                                        do c1 = 1, nc
                                            if (present(kd)) then
                                                i1 = m1 + ncol*(c1 - 1)
                                                i2 = m2 + ncol*(c2 - 1)
                                                kd(i1, i2) = kd(i1, i2) + v* &
                                                    gr%jac(c1 + nc*(d1 - 1), c2 + nc*(d2 - 1), e)
                                            else
                                                i1 = c1 + nc*(iperm(gg%i(k1)) - 1)
                                                i2 = c2 + nc*(iperm(gg%i(k2)) - 1)
                                                call band_add(kb, i1, i2, v*gr%jac(c1 + &
                                                    nc*(d1 - 1), c2 + nc*(d2 - 1), e), ok)
                                            end if
                                        end do
                                    end do
                                end do
                            end do
                        end do
                    end do
                end do
            end associate
        end do
        if (.not. ok) call set_status(info, FRIROM_ERR_MODEL, errmsg, &
                                      'contact_assemble: entry outside the band')
    end procedure contact_assemble

    !> How contact_eval maps the group's rows of G (once per contact set; G is fixed):
    !> by matrix products over the ns columns the group reads when its rows are dense over
    !> them (ns (ne ndir) <= 2 nnz: GSI coordinates), else by the sparse rows. The
    !> products sum in another order than the rows: same results to rounding.
    subroutine choose_gx(gr, gg, nc)
        type(contact_group), intent(inout) :: gr
        type(csr_matrix), intent(in) :: gg
        integer(ip), intent(in) :: nc
        integer(ip), allocatable :: pos(:)
        integer(ip) :: ns, nrg, k1, k2, k, stat
        gr%gx_mode = 1
        nrg = gr%ne*gr%ndir
        k1 = gg%p(gr%row0 + 1)
        k2 = gg%p(gr%row0 + nrg + 1) - 1
        if (k2 < k1) return
        allocate (pos(gg%ncol), stat=stat)
        if (stat /= 0) return
        pos = 0
        do k = k1, k2       ! (a vector subscript with repeated columns may not be assigned)
            pos(gg%i(k)) = 1
        end do
        ns = count(pos /= 0)
        if (real(ns, wp)*real(nrg, wp) > 2.0_wp*real(k2 - k1 + 1, wp)) then
            call choose_dir(gr, gg, nc, pos, k2 - k1 + 1)
            return
        end if
        if (.not. allocated(gr%gt)) call group_gt(gr, gg, pos)
        if (.not. allocated(gr%gt)) return
        allocate (gr%gxs(ns, nc), stat=stat)
        if (stat /= 0) return
        gr%gx_mode = 2
    end subroutine choose_gx

    !> gx_mode 3 when the rows of each direction are dense over the columns that direction
    !> reads (sum_d ns_d ne <= 2 nnz: MS coordinates, each one cylindrical component, read
    !> by a third of the rows), with gr%dcols / dptr / gdt / gxs built; else the group keeps
    !> its sparse rows (mode 1). pos: (ncol) work.
    subroutine choose_dir(gr, gg, nc, pos, nnz)
        type(contact_group), intent(inout) :: gr
        type(csr_matrix), intent(in) :: gg
        integer(ip), intent(in) :: nc, nnz
        integer(ip), intent(inout) :: pos(:)
        integer(ip) :: nd, d, e, k, r, n, m, stat
        nd = gr%ndir
        if (nd < 1 .or. gr%ne < 1) return
        n = 0
        do d = 1, nd
            call mark(d)
            n = n + count(pos /= 0)
        end do
        if (real(n, wp)*real(gr%ne, wp) > 2.0_wp*real(nnz, wp)) return
        allocate (gr%dcols(n), gr%dptr(nd + 1), gr%gdt(max(n, 1), gr%ne), stat=stat)
        if (stat /= 0) return
        gr%gdt = 0.0_wp
        gr%dptr(1) = 1
        n = 0
        m = 0
        do d = 1, nd
            call mark(d)
            do k = 1, gg%ncol       ! the columns ascending; pos(col) = their row in gdt
                if (pos(k) == 0) cycle
                n = n + 1
                pos(k) = n
                gr%dcols(n) = k
            end do
            gr%dptr(d + 1) = n + 1
            m = max(m, gr%dptr(d + 1) - gr%dptr(d))
            do e = 1, gr%ne
                r = gr%row0 + (e - 1)*nd + d
                do k = gg%p(r), gg%p(r + 1) - 1
                    gr%gdt(pos(gg%i(k)), e) = gr%gdt(pos(gg%i(k)), e) + gg%x(k)
                end do
            end do
        end do
        if (allocated(gr%gxs)) deallocate (gr%gxs)
        allocate (gr%gxs(max(m, 1), nc), stat=stat)
        if (stat /= 0) then
            deallocate (gr%dcols, gr%dptr, gr%gdt)
            return
        end if
        gr%gx_mode = 3

    contains

        !> pos = 1 on the columns direction d's rows read, 0 elsewhere.
        subroutine mark(d)
            integer(ip), intent(in) :: d
            integer(ip) :: ee, kk, rr
            pos = 0
            do ee = 1, gr%ne
                rr = gr%row0 + (ee - 1)*nd + d
                do kk = gg%p(rr), gg%p(rr + 1) - 1
                    pos(gg%i(kk)) = 1
                end do
            end do
        end subroutine mark
    end subroutine choose_dir

    !> gr%gcols (the columns the group's rows read, ascending; pos(col) /= 0 marks them on
    !> entry, becomes the index in gcols) and gr%gt = those rows over gcols, transposed.
    !> Left unallocated when memory runs out (the callers then take the sparse rows).
    subroutine group_gt(gr, gg, pos)
        type(contact_group), intent(inout) :: gr
        type(csr_matrix), intent(in) :: gg
        integer(ip), intent(inout) :: pos(:)       !! (ncol) marks in, index in gcols out
        integer(ip) :: k, r, ns, nrg, stat
        nrg = gr%ne*gr%ndir
        ns = count(pos /= 0)
        allocate (gr%gcols(ns), gr%gt(ns, nrg), stat=stat)
        if (stat /= 0) then
            if (allocated(gr%gcols)) deallocate (gr%gcols)
            if (allocated(gr%gt)) deallocate (gr%gt)
            return
        end if
        ns = 0
        do k = 1, gg%ncol
            if (pos(k) == 0) cycle
            ns = ns + 1
            pos(k) = ns
            gr%gcols(ns) = k
        end do
        gr%gt = 0.0_wp
        do r = 1, nrg
            do k = gg%p(gr%row0 + r), gg%p(gr%row0 + r + 1) - 1
                gr%gt(pos(gg%i(k)), r) = gr%gt(pos(gg%i(k)), r) + gg%x(k)
            end do
        end do
    end subroutine group_gt

    !> kd += G_g^T J_loc G_g of one contact group by matrix products when its rows are
    !> dense over the columns they read (an interface reduced to a few generalised DoFs):
    !> with S the group's columns (ns of them, gr%gcols) and Gd (nrg, ns) its rows (gr%gt
    !> = Gd^T, shared with contact_eval), Y_c1 = (J_e G_e) rows of harmonic c1 over all
    !> elements, kd(S c1, S :) += Gd^T Y_c1 (one dgemm per harmonic coefficient c1). The
    !> choice (gr%asm_mode) and the work arrays stay with the group between calls.
    !> done = .false. (nothing added): the rows are sparse, the element loops of
    !> contact_assemble are cheaper.
    subroutine assemble_dense(gr, gg, nc, ldc, kd, info, errmsg, done, colmap)
        type(contact_group), intent(inout) :: gr
        type(csr_matrix), intent(in) :: gg
        integer(ip), intent(in) :: nc, ldc               !! coefficients, harmonic stride
        real(wp), intent(inout) :: kd(:, :)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        logical, intent(out) :: done
        integer(ip), intent(in), optional :: colmap(:)
        integer(ip), allocatable :: cols(:)
        integer(ip) :: nd, ne, nrg, ns, e, d1, d2, c1, c2, r, s1, s2, m1, m2
        real(wp) :: v
        info = FRIROM_OK
        done = .false.
        if (gr%asm_mode == 0) call choose_dense(gr, gg)
        if (gr%asm_mode /= 2) return
        nd = gr%ndir
        ne = gr%ne
        nrg = ne*nd
        ns = size(gr%gcols)
        if (allocated(gr%yt)) then
            if (any(shape(gr%yt) /= [ns*nc, nrg])) deallocate (gr%yt, gr%kt)
        end if
        if (.not. allocated(gr%yt)) then
            allocate (gr%yt(ns*nc, nrg), gr%kt(ns, ns*nc), stat=r)
            if (r /= 0) then
                if (allocated(gr%yt)) deallocate (gr%yt)
                return                          ! the element loops need no workspace
            end if
        end if
        cols = gr%gcols
        if (present(colmap)) cols = colmap(cols)
        if (any(cols < 1) .or. any(cols > ldc) .or. size(kd, 1) < ldc*nc .or. &
            size(kd, 2) < ldc*nc) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'contact_assemble: a column '// &
                            'outside the dense matrix')
            return
        end if
        associate (gt => gr%gt, yt => gr%yt, kt => gr%kt)
            do c1 = 1, nc
                ! yt(s2 + ns (c2-1), (e-1) nd + d1) = sum_d2 J_e(c1 d1, c2 d2) G(e d2, s2)
                yt = 0.0_wp
                do e = 1, ne
                    do d1 = 1, nd
                        r = (e - 1)*nd + d1
                        do c2 = 1, nc
                            do d2 = 1, nd
                                v = gr%jac(c1 + nc*(d1 - 1), c2 + nc*(d2 - 1), e)
                                if (v == 0.0_wp) cycle
                                yt(ns*(c2 - 1) + 1:ns*c2, r) = yt(ns*(c2 - 1) + 1:ns*c2, r) &
                                                               + v*gt(:, (e - 1)*nd + d2)
                            end do
                        end do
                    end do
                end do
                call dgemm('N', 'T', ns, ns*nc, nrg, 1.0_wp, gt, ns, yt, ns*nc, 0.0_wp, &
                           kt, ns)
                do c2 = 1, nc
                    do s2 = 1, ns
                        m2 = cols(s2) + ldc*(c2 - 1)
                        do s1 = 1, ns
                            m1 = cols(s1) + ldc*(c1 - 1)
                            kd(m1, m2) = kd(m1, m2) + kt(s1, s2 + ns*(c2 - 1))
                        end do
                    end do
                end do
            end do
        end associate
        done = .true.
    end subroutine assemble_dense

    !> gr%asm_mode (once per contact set; G is fixed): 2 when assemble_dense's products
    !> pay, with gr%gcols / gr%gt built if contact_eval has not; else 1. BLAS runs the
    !> products ~10x faster than the scalar loops: take them up to 4x the loops'
    !> operations (dense GSI columns: nd times fewer).
    module subroutine choose_dense(gr, gg)
        type(contact_group), intent(inout) :: gr
        type(csr_matrix), intent(in) :: gg
        integer(ip), allocatable :: pos(:)
        integer(ip) :: nd, ns, r0, e, k, stat
        real(wp) :: sparse_cost
        gr%asm_mode = 1
        nd = gr%ndir
        r0 = gr%row0
        allocate (pos(gg%ncol), stat=stat)
        if (stat /= 0) return
        pos = 0
        sparse_cost = 0.0_wp
        do e = 1, gr%ne
            k = gg%p(r0 + e*nd + 1) - gg%p(r0 + (e - 1)*nd + 1)
            sparse_cost = sparse_cost + real(k, wp)**2
            do k = gg%p(r0 + (e - 1)*nd + 1), gg%p(r0 + e*nd + 1) - 1
                pos(gg%i(k)) = 1
            end do
        end do
        ns = count(pos /= 0)
        if (ns == 0 .or. real(ns, wp)**2*real(gr%ne*nd, wp) > 4.0_wp*sparse_cost) return
        if (.not. allocated(gr%gt)) call group_gt(gr, gg, pos)
        if (allocated(gr%gt)) gr%asm_mode = 2
    end subroutine choose_dense

    module procedure hbm_contact_forces
        integer(ip) :: i, nc
        real(wp), allocatable :: yf(:), fz(:)
        real(wp) :: t0
        logical :: count, orb
        count = .false.
        if (present(timed)) count = timed
        orb = .false.
        if (present(orbits)) orb = orbits
        if (present(carry)) orb = orb .and. .not. carry
        nc = sys%nc
        select type (sys)
        type is (hbm_condensed)
            if (allocated(sys%tk)) then
                ! a selection with pairs: the kept unknowns are T y
                allocate (yf(size(sys%xd)))
                call hbm_sel_expand(sys, y, yf)
                sys%xd = reshape(yf, [sys%nnl, nc])
            else if (allocated(sys%sel)) then
                ! a selection (hbm_set_selection): the pairs left out are zero
                sys%xd = 0.0_wp
                do i = 1, size(sys%sel)
                    sys%xd(mod(sys%sel(i) - 1, sys%nnl) + 1, (sys%sel(i) - 1)/sys%nnl + 1) = y(i)
                end do
            else
                sys%xd = reshape(y, [sys%nnl, nc])
            end if
        class default
            do i = 1, sys%ndof
                sys%xd(i, :) = y(nc*(sys%iperm(i) - 1) + 1:nc*sys%iperm(i))
            end do
        end select
        t0 = wtime()
        select type (sys)
        type is (hbm_condensed)
            if (orb .and. sys%orbits) then
                ! one element per orbit; fd = T (T^T G^T f), the wave's forces
                allocate (fz(sys%n))
                call orbit_forces(sys, y, jac, fz, info, errmsg)
                if (info == 0) then
                    call hbm_sel_expand(sys, fz, yf)
                    sys%fd = reshape(yf, [sys%nnl, nc])
                end if
            else if (allocated(sys%sel)) then
                call contact_eval(sys%cs, sys%plan, sys%xd, sys%fd, jac, info, errmsg, carry, &
                                  keep=sys%kmask)
            else
                call contact_eval(sys%cs, sys%plan, sys%xd, sys%fd, jac, info, errmsg, carry)
            end if
        class default
            call contact_eval(sys%cs, sys%plan, sys%xd, sys%fd, jac, info, errmsg, carry)
        end select
        if (.not. count) return
        sys%timers(T_AFT) = sys%timers(T_AFT) + wtime() - t0
        sys%timers(N_EVAL) = sys%timers(N_EVAL) + 1
    end procedure hbm_contact_forces

    module procedure hbm_accept
        info = FRIROM_OK
        if (.false.) info = int(lam)
        if (size(this%cs%grp) == 0 .or. .not. this%carry) return
        call hbm_contact_forces(this, y, .false., info, errmsg, carry=.true.)
    end procedure hbm_accept

    module procedure hbm_settled
        yes = this%cs%settled
    end procedure hbm_settled

    module procedure hbm_begin_correct
        integer(ip) :: g
        if (.not. allocated(this%cs%grp)) return
        do g = 1, size(this%cs%grp)
            if (allocated(this%cs%grp(g)%held)) this%cs%grp(g)%held = 0
        end do
    end procedure hbm_begin_correct

    module procedure hbm_slider_offsets
        integer(ip) :: g
        allocate (k0(size(sys%cs%grp) + 1))
        k0(1) = 0
        do g = 1, size(sys%cs%grp)
            k0(g + 1) = k0(g) + law_nslider(sys%cs%grp(g)%law)*sys%cs%grp(g)%ne
        end do
    end procedure hbm_slider_offsets

    module procedure hbm_sliders
        integer(ip), allocatable :: k0(:)
        integer(ip) :: g
        k0 = hbm_slider_offsets(sys)
        do g = 1, size(k0) - 1
            if (k0(g + 1) == k0(g)) cycle
            w(k0(g) + 1:k0(g + 1)) = reshape(sys%cs%grp(g)%w0(1:(k0(g + 1) - k0(g))/ &
                                             sys%cs%grp(g)%ne, :), [k0(g + 1) - k0(g)])
        end do
    end procedure hbm_sliders

    module procedure hbm_set_sliders
        integer(ip), allocatable :: k0(:)
        integer(ip) :: g, ne
        k0 = hbm_slider_offsets(sys)
        do g = 1, size(k0) - 1
            ne = sys%cs%grp(g)%ne
            if (k0(g + 1) > k0(g)) sys%cs%grp(g)%w0(1:(k0(g + 1) - k0(g))/ne, :) = &
                reshape(w(k0(g) + 1:k0(g + 1)), [(k0(g + 1) - k0(g))/ne, ne])
        end do
    end procedure hbm_set_sliders

end submodule frirom_hbm_contacts
