!> The condensed formulation of frirom_hbm (Eq. 5-9 of the reference) in the coordinates
!> u = T x (T = P: the nonlinear DoFs; T = G: the contacts' local relative displacements):
!> the residual R = U - T X_e + R_h F_c(U) with the receptances R_h = T D_h^-1 T^T of
!> frirom_hbm_receptances, J = I + R_h dF_c/dU assembled element by element (dF_c/dU is
!> block diagonal per contact element), its LU or GMRES on it preconditioned by an older
!> LU, and the outputs by Eq. 9.
!>
!> This submodule holds the set-up, the residual and the outputs, and declares the
!> procedures its own submodules share (one job each):
!>   frirom_hbm_select.f90    the travelling-wave selection and its pairs, the leaks
!>   frirom_hbm_keptrows.f90  a selection's kept mode rows: the residual's projections
!>   frirom_hbm_jacobian.f90  J element by element, and on a selection's kept unknowns
!>   frirom_hbm_factor.f90    LU, solves (GMRES on frirom_linsolve), the LU carried
submodule (frirom_hbm) frirom_hbm_condensed
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_ALLOC, set_status
    implicit none

    ! ---- shared by the submodules of frirom_hbm_condensed ------------------------------
    interface
        !> J = I + R_h dF_c/dU in real harmonic form, element by element: dF_c/dU is
        !> G_e^T J_e G_e on the coordinates S_e element e reads, so J's columns (S_e, all
        !> harmonics) receive [A_h B_h](:, S_e) times that block (R_h = A_h + i B_h); then
        !> the dense LU.
        module subroutine cond_jacobian(sys, info, errmsg)
            type(hbm_condensed), intent(inout) :: sys
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine cond_jacobian

        !> J of a selected system (hbm_set_selection) on its kept rows and columns: kc, the
        !> kept part of dF_c/dU in y's order, by products over each contact group's dense
        !> rows (gr%gt) or taken from the element loops, then J = I + R_h kc with R_h on the
        !> coordinates kept at harmonic h only (exact for a tuned rotor, whose R_h does not
        !> couple the index families), then the LU.
        module subroutine cond_jacobian_sel(sys, info, errmsg)
            type(hbm_condensed), intent(inout) :: sys
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine cond_jacobian_sel

        !> LU of J (jm := jcur first in Krylov mode). Systems that hold their LU
        !> (cond_lu_holds) factorise a single-precision copy (held%lus): half the flops of the LU
        !> and half the memory traffic of each triangular solve; it only preconditions GMRES
        !> (cond_solve) and jm keeps J for a double LU (double) if that GMRES stalls.
        module subroutine cond_factor(sys, info, errmsg, double)
            type(hbm_condensed), intent(inout) :: sys
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
            logical, intent(in), optional :: double
        end subroutine cond_factor

        !> Whether sys keeps LUs (single precision, carried across runs): modal, direct mode,
        !> no selection, an LU worth at least GN_WORTH_MIN GMRES iterations.
        pure module function holds(sys)
            type(hbm_condensed), intent(in) :: sys
            logical :: holds
        end function holds

        !> lu_worth of sys (modal route), kept in gm_worth.
        module function gm_cost(sys)
            type(hbm_condensed), intent(inout) :: sys
            real(wp) :: gm_cost
        end function gm_cost

        !> The cache of a selection's kept mode rows (prow, pamx, pan; see hbm_condensed),
        !> (re)built when missing or made for other modes or another selection.
        module subroutine sel_rows(sys)
            type(hbm_condensed), intent(inout) :: sys
        end subroutine sel_rows

        !> v = A^H fc (the modal route with a selection, real modes) on the modes use(1:nuse)
        !> that reach harmonic h's kept rows (sel_modes), or on all when the terms left out
        !> are not negligible against those computed (proj_safe); v is zero on the others.
        module subroutine sel_project(sys, h, s, fc, v, use, nuse)
            type(hbm_condensed), intent(inout) :: sys
            integer(ip), intent(in) :: h
            real(wp), intent(in) :: s
            complex(wp), intent(in) :: fc(:)
            complex(wp), intent(out) :: v(:)
            integer(ip), allocatable, intent(inout) :: use(:)
            integer(ip), intent(out) :: nuse
        end subroutine sel_project

        !> v = A^H fc on every mode when fc is zero off harmonic h's kept rows (the orbits'
        !> forces, T fz): over those rows only, from the cached prow, without gathering.
        module subroutine project_kept(sys, h, fc, v)
            type(hbm_condensed), intent(in) :: sys
            integer(ip), intent(in) :: h
            complex(wp), intent(in) :: fc(:)
            complex(wp), intent(out) :: v(:)
        end subroutine project_kept

        !> modal_rows over the modes use only: b(kept rows at h, :) = A_h(those rows, use)
        !> x(use, :) from the cached rows prow; the other rows of b zero.
        module subroutine rows_some(sys, h, use, x, b)
            type(hbm_condensed), intent(in) :: sys
            integer(ip), intent(in) :: h, use(:)
            complex(wp), intent(in) :: x(:, :)     !! (nm, k)
            complex(wp), intent(out) :: b(:, :)    !! (nnl, k)
        end subroutine rows_some

        !> Modal route, a selection: b(rows, :) = A_h(rows, :) x, the other rows of b zero.
        module subroutine modal_rows(sys, h, rows, x, b)
            type(hbm_condensed), intent(in) :: sys
            integer(ip), intent(in) :: h, rows(:)
            complex(wp), intent(in) :: x(:, :)     !! (nm, k)
            complex(wp), intent(out) :: b(:, :)    !! (nnl, k)
        end subroutine modal_rows

        !> xe_leak at the receptances' frequency and load factor s: |T X_e off the selection|
        !> / |on it|, T X_e the loads' linear response at the coordinates (every row; the
        !> residual keeps only the kept ones).
        module subroutine load_leak(sys, s)
            type(hbm_condensed), intent(inout) :: sys
            real(wp), intent(in) :: s
        end subroutine load_leak

        !> orb_leak at y, after a contact_eval of every element there (sys%fd): |T^T fd - the
        !> orbits' forces| / |the orbits' forces|, what Newton's evaluations left out.
        module subroutine orbit_leak(sys, y, info, errmsg)
            type(hbm_condensed), intent(inout) :: sys
            real(wp), intent(in) :: y(:)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine orbit_leak

        !> Whether a selected system's contact forces (sys%fd, real modes) off the kept rows
        !> are below OUT_SKIP of those on them, so that the outputs may leave them out: their
        !> response is at most that fraction times the amplification of a mode off the
        !> selection over one on it (1 / (2 zeta): 250 for the flange's 0.2 %), ~1e-10 of the
        !> outputs, below Newton's tolerance. Refreshes the kept mode rows (sel_rows).
        module function sel_only(sys)
            type(hbm_condensed), intent(inout) :: sys
            logical :: sel_only
        end function sel_only
    end interface

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
                  sys%ai(nu, nu, 0:sys%nh), sys%jm(n, n), sys%held%ipiv(n), stat=stat)
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
        if (jac) then
            ! where a J comes from (hbm_lu_state)
            this%jy = y
            this%jlam = lam
        end if
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
            if (this%lu_any .and. holds(this)) then
                if (this%gm_spent < gm_cost(this)) then
                    ! J for products only, the LU stays: the next solve by GMRES (cond_solve)
                    this%jfree = .true.
                    this%gm_next = .true.
                    this%lu_fresh = .false.
                    return
                end if
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

    module procedure cond_outputs
        real(wp) :: w, s
        integer(ip) :: h, j, o, nu, nout, nm
        complex(wp), allocatable :: fc(:), z(:), v(:), x1(:, :), b1(:, :)
        real(wp), allocatable :: fr(:, :), vr(:, :)
        logical :: kept
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
        kept = .false.
        if (allocated(this%phr)) kept = sel_only(this)
        if (kept) then
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
end submodule frirom_hbm_condensed
