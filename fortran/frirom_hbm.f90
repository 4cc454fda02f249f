!> Harmonic balance equations of M x'' + C x' + K x + G^T f(G x) = f_e in real harmonic
!> form (per DoF: [a0, a1, b1, ..., aH, bH], x = a0 + sum a_h cos(h tau) + b_h sin(h tau)),
!> with their analytical Jacobian, in two formulations that give the same solution:
!>
!> * hbm_condensed (Eq. 5-9 of the reference): unknowns are the harmonics of the nonlinear
!>   DoFs only (column support of all G), R = X_n - X_e,n + H_nn F_c(X_n), receptances from
!>   a banded factorisation of D_h = K + i h w C - (h w)^2 M per harmonic, refreshed only
!>   when the frequency changes; J = I + H_nn dF_c/dX_n (dense LU). Outputs by Eq. 9.
!> * hbm_full: all DoFs x harmonics, R = D X + F_c(X) - F_e, unknowns ordered DoF by DoF in
!>   a reverse Cuthill-McKee order so that J is banded (LAPACK dgbtrf).
!>
!> The parameter lam is the frequency w (mode 1, excitation fe0) or a load factor (mode 2,
!> excitation fe0 + lam fe1 at the fixed frequency omega_fix). Contact groups go through
!> the AFT kernel (frirom_aft) with one plan made when the system is built.
!> K, M and C must be symmetric (the condensed dR/dw uses D_h^T = D_h). The condensed
!> receptances may instead come from modes: the same real modes for every harmonic
!> (hbm_set_modes) or complex modes of their own per harmonic (hbm_set_modes_harmonic, a
!> cyclic sector whose harmonic h lives on nodal diameter h EO mod N); K, M, C are then
!> not used and may be empty.
module frirom_hbm
    use frirom_kinds, only: wp, ip
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_PARAM, &
                             FRIROM_ERR_ALLOC, FRIROM_ERR_LAPACK, FRIROM_ERR_SINGULAR, &
                             FRIROM_ERR_MODEL, FRIROM_ERR_LAW, FRIROM_ERR_NONFINITE, set_status
    use frirom_banded, only: band_matrix, zband_matrix, band_init, band_zero, band_add, &
                             band_factor, band_solve, zband_init, zband_zero, zband_add, &
                             zband_factor, zband_solve
    use frirom_newton, only: nl_system, cont_options, newton_correct, cont_tangent, cont_run
    use frirom_aft, only: aft_plan, aft_plan_create, aft_plan_destroy, aft_eval, law_ndir, &
                          law_npar, law_nslider
    implicit none
    private
    public :: csr_matrix, contact_group, contact_set, hbm_system, hbm_condensed, hbm_full, &
              hbm_setup, hbm_set_modes, hbm_set_modes_harmonic, hbm_run, hbm_hill, &
              hbm_sliders, contact_eval, contact_assemble, &
              HBM_FREQUENCY, HBM_LOAD, &
              T_AFT, T_ASM, T_FACT, T_SOLVE, T_REC, N_EVAL, N_FACT, N_TIMERS

    integer(ip), parameter :: HBM_FREQUENCY = 1, HBM_LOAD = 2
    !> Indices of the timers/counters in hbm_system%timers: AFT, Jacobian assembly,
    !> factorisation, solves, receptances (s); residual evaluations, factorisations.
    integer(ip), parameter :: T_AFT = 1, T_ASM = 2, T_FACT = 3, T_SOLVE = 4, T_REC = 5, &
                              N_EVAL = 6, N_FACT = 7, N_TIMERS = 8

    !> Sparse matrix in compressed sparse row form, 1-based.
    type :: csr_matrix
        integer(ip) :: nrow = 0, ncol = 0
        integer(ip), allocatable :: p(:)   !! (nrow+1) row pointers
        integer(ip), allocatable :: i(:)   !! (nnz) column indices
        real(wp), allocatable :: x(:)      !! (nnz) values
    end type csr_matrix

    !> One group of contact elements with the same law, and its AFT workspaces.
    type :: contact_group
        integer(ip) :: law = 0, ne = 0, ndir = 0, row0 = 0  !! row0: rows before it in G
        real(wp), allocatable :: params(:, :)   !! (npar, ne)
        real(wp), allocatable :: w0(:, :)       !! (nslider, ne)
        real(wp), allocatable :: x(:, :, :)     !! (nc, ndir, ne) local displacements
        real(wp), allocatable :: f(:, :, :)     !! (nc, ndir, ne) local forces
        real(wp), allocatable :: jac(:, :, :)   !! (nc ndir, nc ndir, ne)
        real(wp), allocatable :: states(:, :)   !! (3, ne) stick, slip, lift-off fractions
    end type contact_group

    !> All contact groups; G maps the model's columns (full DoFs or nonlinear DoFs) to the
    !> local relative displacements, rows group by group, element by element, direction.
    type :: contact_set
        integer(ip) :: nc = 0
        type(csr_matrix) :: g
        type(contact_group), allocatable :: grp(:)
    end type contact_set

    !> Data shared by both formulations.
    type, abstract, extends(nl_system) :: hbm_system
        integer(ip) :: ndof = 0, nh = 0, nc = 0, mode = HBM_FREQUENCY
        real(wp) :: omega_fix = 0.0_wp
        type(csr_matrix) :: k, m, c
        integer(ip), allocatable :: perm(:), iperm(:)   !! RCM order of the DoFs
        integer(ip) :: bw = 0                           !! DoF half-bandwidth under perm
        real(wp), allocatable :: fe0(:, :), fe1(:, :)   !! (ndof, nc) excitation, load part
        integer(ip), allocatable :: outdofs(:)          !! output DoFs
        type(contact_set) :: cs
        type(aft_plan) :: plan
        real(wp) :: timers(N_TIMERS) = 0.0_wp
        !> accept carries the contact history (sliders) from point to point; .false.
        !> restarts every AFT call from the w0 given at setup
        logical :: carry = .true.
    contains
        procedure(outputs_iface), deferred :: outputs
        procedure :: accept => hbm_accept
    end type hbm_system

    abstract interface
        !> Harmonics xo(nout, nc) at the output DoFs for a solution y at lam (after an eval
        !> at that point).
        subroutine outputs_iface(this, y, lam, xo, info, errmsg)
            import :: hbm_system, wp, ip
            class(hbm_system), intent(inout) :: this
            real(wp), intent(in) :: y(:), lam
            real(wp), intent(out) :: xo(:, :)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine outputs_iface
    end interface

    !> Condensed formulation: y(j + nnl (c-1)) = harmonic coefficient c of nonlinear DoF j.
    type, extends(hbm_system) :: hbm_condensed
        integer(ip) :: nnl = 0
        integer(ip), allocatable :: nl(:)                !! (nnl) nonlinear DoFs
        real(wp) :: w_cache = -1.0_wp
        type(zband_matrix) :: d                          !! work: D_h, banded, RCM order
        complex(wp), allocatable :: ymat(:, :, :)        !! (ndof, nnl, 0:nh) D_h^-1 P^T
        complex(wp), allocatable :: ye0(:, :), ye1(:, :) !! (ndof, 0:nh) D_h^-1 fe
        real(wp), allocatable :: ar(:, :, :), ai(:, :, :) !! (nnl, nnl, 0:nh) Re, Im H_nn
        real(wp), allocatable :: kc(:, :), jm(:, :)      !! (n, n) contact Jacobian, J
        integer(ip), allocatable :: ipiv(:)
        real(wp), allocatable :: xd(:, :), fd(:, :)      !! (nnl, nc)
        !> modal superposition instead of factorising D_h (hbm_set_modes, or
        !> hbm_set_modes_harmonic: modes of their own for every harmonic)
        logical :: modal = .false.
        !> (nr) DoFs where psi is kept: the nl DoFs first (rows 1..nnl), then the other
        !> output DoFs
        integer(ip), allocatable :: mrow(:)
        complex(wp), allocatable :: psi(:, :, :)         !! (nr, nm, 0:nh) mode shapes
        real(wp), allocatable :: wm(:, :), zm(:, :)      !! (nm, 0:nh) rad/s, damping ratios
        complex(wp), allocatable :: dg(:, :)             !! (nm, 0:nh) d g_r / d w
        complex(wp), allocatable :: qf(:, :), qf1(:, :)  !! (nm, 0:nh) Psi_h^H fe0_h, fe1_h
    contains
        procedure :: eval => cond_eval
        procedure :: solve => cond_solve
        procedure :: outputs => cond_outputs
    end type hbm_condensed

    !> Full banded formulation: y(c + nc (iperm(i)-1)) = coefficient c of DoF i.
    type, extends(hbm_system) :: hbm_full
        type(band_matrix) :: jb
        real(wp), allocatable :: xd(:, :), fd(:, :), rd(:, :)  !! (ndof, nc)
    contains
        procedure :: eval => full_eval
        procedure :: solve => full_solve
        procedure :: outputs => full_outputs
    end type hbm_full

contains

    !> Wall-clock seconds.
    function wtime() result(t)
        real(wp) :: t
        integer(kind=8) :: cnt, rate
        call system_clock(cnt, rate)
        t = real(cnt, wp)/real(rate, wp)
    end function wtime

    !> y += alpha A x for the columns of x (A in CSR).
    pure subroutine csr_matvec_add(a, x, y, alpha)
        type(csr_matrix), intent(in) :: a
        real(wp), intent(in) :: x(:)
        real(wp), intent(inout) :: y(:)
        real(wp), intent(in) :: alpha
        integer(ip) :: i, k
        real(wp) :: s
        do i = 1, a%nrow
            s = 0.0_wp
            do k = a%p(i), a%p(i + 1) - 1
                s = s + a%x(k)*x(a%i(k))
            end do
            y(i) = y(i) + alpha*s
        end do
    end subroutine csr_matvec_add

    !> Check and copy a CSR matrix (nrow x ncol, 1-based).
    subroutine csr_set(a, nrow, ncol, p, i, x, name, info, errmsg)
        type(csr_matrix), intent(out) :: a
        integer(ip), intent(in) :: nrow, ncol, p(:), i(:)
        real(wp), intent(in) :: x(:)
        character(len=*), intent(in) :: name
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: nnz
        info = FRIROM_OK
        if (size(p) /= nrow + 1) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, name//': row pointer length')
            return
        end if
        nnz = p(nrow + 1) - 1
        if (p(1) /= 1 .or. nnz < 0 .or. nnz > size(i) .or. nnz > size(x) .or. &
            any(p(2:) < p(:nrow))) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, name//': malformed CSR pointers')
            return
        end if
        if (nnz > 0) then
            if (any(i(:nnz) < 1) .or. any(i(:nnz) > ncol)) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, name//': column out of range')
                return
            end if
            if (.not. all(abs(x(:nnz)) <= huge(1.0_wp))) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, name//': non-finite value')
                return
            end if
        end if
        a%nrow = nrow
        a%ncol = ncol
        a%p = p
        a%i = i(:nnz)
        a%x = x(:nnz)
    end subroutine csr_set

    !> Build a system (condensed or full) from plain arrays; see frirom_f2py hbm_continue
    !> for the meaning of each argument. `nl` is used by the condensed formulation only.
    subroutine hbm_setup(sys, nh, nsamp, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, &
                         nl, fe0, fe1, mode, omega_fix, ginfo, gp, gi, gx, params, w0, &
                         outdofs, info, errmsg)
        class(hbm_system), intent(inout) :: sys
        integer(ip), intent(in) :: nh, nsamp, ndof
        integer(ip), intent(in) :: kp(:), ki(:), mp(:), mi(:), cp(:), ci(:)
        real(wp), intent(in) :: kx(:), mx(:), cx(:)
        integer(ip), intent(in) :: perm(:)       !! (ndof) RCM order of the DoFs
        integer(ip), intent(in) :: nl(:)         !! (nnl) nonlinear DoFs, sorted
        real(wp), intent(in) :: fe0(:, :), fe1(:, :)  !! (ndof, 2nh+1)
        integer(ip), intent(in) :: mode
        real(wp), intent(in) :: omega_fix
        integer(ip), intent(in) :: ginfo(:, :)   !! (3, ngroup): law, ne, ndir
        integer(ip), intent(in) :: gp(:), gi(:)  !! G in CSR over the full DoFs
        real(wp), intent(in) :: gx(:)
        real(wp), intent(in) :: params(:)        !! (npar, ne) per group, concatenated
        real(wp), intent(in) :: w0(:)            !! (nslider, ne) per group, concatenated
        integer(ip), intent(in) :: outdofs(:)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: nc, ng, g, nrows, row, ip0, iw0, npar, nsl, ne, nd, i, k, ncol, nnl
        integer(ip), allocatable :: colmap(:), gi2(:)
        integer(ip) :: stat
        info = FRIROM_OK
        nc = 2*nh + 1
        if (nh < 0 .or. ndof < 1) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'hbm_setup: need H >= 0, ndof >= 1')
            return
        end if
        if (size(perm) /= ndof .or. size(fe0, 1) /= ndof .or. size(fe0, 2) /= nc .or. &
            any(shape(fe1) /= shape(fe0))) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'hbm_setup: perm or excitation size')
            return
        end if
        if (mode /= HBM_FREQUENCY .and. mode /= HBM_LOAD) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'hbm_setup: mode must be 1 or 2')
            return
        end if
        sys%nh = nh
        sys%nc = nc
        sys%ndof = ndof
        sys%mode = mode
        sys%omega_fix = omega_fix
        call csr_set(sys%k, ndof, ndof, kp, ki, kx, 'K', info, errmsg)
        if (info /= 0) return
        call csr_set(sys%m, ndof, ndof, mp, mi, mx, 'M', info, errmsg)
        if (info /= 0) return
        call csr_set(sys%c, ndof, ndof, cp, ci, cx, 'C', info, errmsg)
        if (info /= 0) return
        allocate (sys%iperm(ndof))
        sys%perm = perm
        sys%iperm = 0
        do i = 1, ndof
            if (perm(i) < 1 .or. perm(i) > ndof) exit
            sys%iperm(perm(i)) = i
        end do
        if (any(sys%iperm == 0)) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'hbm_setup: perm is not a '// &
                            'permutation of 1..ndof')
            return
        end if
        sys%fe0 = fe0
        sys%fe1 = fe1
        if (any(outdofs < 1) .or. any(outdofs > ndof)) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'hbm_setup: output DoF out of range')
            return
        end if
        sys%outdofs = outdofs
        ! bandwidth of K, M, C and the contact couplings under perm
        sys%bw = max(pattern_bw(sys%k), pattern_bw(sys%m), pattern_bw(sys%c))
        ! contact groups; the condensed formulation renumbers G's columns to nl
        ng = size(ginfo, 2)
        nrows = 0
        do g = 1, ng
            if (size(ginfo, 1) < 3) exit
            nrows = nrows + ginfo(2, g)*ginfo(3, g)
        end do
        if (size(ginfo, 1) < 3 .or. size(gp) /= nrows + 1) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'hbm_setup: G rows do not match '// &
                            'the contact groups')
            return
        end if
        select type (sys)
        type is (hbm_condensed)
            nnl = size(nl)
            if (nnl < 1) then
                call set_status(info, FRIROM_ERR_MODEL, errmsg, 'hbm_setup: the condensed '// &
                                'formulation needs at least one contact DoF')
                return
            end if
            allocate (colmap(ndof))
            colmap = 0
            do i = 1, nnl
                if (nl(i) < 1 .or. nl(i) > ndof) then
                    call set_status(info, FRIROM_ERR_PARAM, errmsg, 'hbm_setup: nl out of range')
                    return
                end if
                colmap(nl(i)) = i
            end do
            k = gp(nrows + 1) - 1
            if (k > size(gi) .or. k < 0) then
                call set_status(info, FRIROM_ERR_SIZE, errmsg, 'hbm_setup: G pointers')
                return
            end if
            allocate (gi2(k))
            do i = 1, k
                if (gi(i) < 1 .or. gi(i) > ndof) then
                    call set_status(info, FRIROM_ERR_PARAM, errmsg, 'G: column out of range')
                    return
                end if
                gi2(i) = colmap(gi(i))
                if (gi2(i) == 0) then
                    call set_status(info, FRIROM_ERR_MODEL, errmsg, 'hbm_setup: a column of '// &
                                    'G is missing from the nonlinear DoF list')
                    return
                end if
            end do
            ncol = nnl
            call csr_set(sys%cs%g, nrows, ncol, gp, gi2, gx, 'G', info, errmsg)
        class default
            ncol = ndof
            call csr_set(sys%cs%g, nrows, ncol, gp, gi, gx, 'G', info, errmsg)
        end select
        if (info /= 0) return
        sys%cs%nc = nc
        allocate (sys%cs%grp(ng))
        row = 0
        ip0 = 0
        iw0 = 0
        do g = 1, ng
            associate (gr => sys%cs%grp(g))
                gr%law = ginfo(1, g)
                ne = ginfo(2, g)
                nd = ginfo(3, g)
                if (gr%law < 1 .or. gr%law > 4) then
                    call set_status(info, FRIROM_ERR_LAW, errmsg, 'hbm_setup: contact group law')
                    return
                end if
                if (nd /= law_ndir(gr%law) .or. ne < 1) then
                    call set_status(info, FRIROM_ERR_SIZE, errmsg, 'hbm_setup: contact group '// &
                                    'directions do not match its law, or no element')
                    return
                end if
                npar = law_npar(gr%law)
                nsl = law_nslider(gr%law)
                if (ip0 + npar*ne > size(params) .or. iw0 + nsl*ne > size(w0)) then
                    call set_status(info, FRIROM_ERR_SIZE, errmsg, 'hbm_setup: params or w0 '// &
                                    'shorter than the groups need')
                    return
                end if
                gr%ne = ne
                gr%ndir = nd
                gr%row0 = row
                gr%params = reshape(params(ip0 + 1:ip0 + npar*ne), [npar, ne])
                allocate (gr%w0(max(nsl, 1), ne))
                gr%w0 = 0.0_wp
                if (nsl > 0) gr%w0(1:nsl, :) = reshape(w0(iw0 + 1:iw0 + nsl*ne), [nsl, ne])
                allocate (gr%x(nc, nd, ne), gr%f(nc, nd, ne), gr%jac(nc*nd, nc*nd, ne), &
                          gr%states(3, ne), stat=stat)
                if (stat /= 0) then
                    call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'hbm_setup: AFT workspaces')
                    return
                end if
                gr%states = 0.0_wp
                row = row + ne*nd
                ip0 = ip0 + npar*ne
                iw0 = iw0 + nsl*ne
            end associate
        end do
        call aft_plan_create(sys%plan, nh, nsamp, info, errmsg)
        if (info /= 0) return
        ! contact couplings widen the band of the full formulation
        do g = 1, ng
            associate (gr => sys%cs%grp(g), gg => sys%cs%g)
                do i = 1, gr%ne
                    row = gr%row0 + (i - 1)*gr%ndir
                    k = elem_bw(gg, row + 1, row + gr%ndir, sys)
                    sys%bw = max(sys%bw, k)
                end do
            end associate
        end do
        select type (sys)
        type is (hbm_condensed)
            call cond_init(sys, nl, info, errmsg)
        type is (hbm_full)
            call full_init(sys, info, errmsg)
        end select

    contains

        pure function pattern_bw(a) result(bw)
            type(csr_matrix), intent(in) :: a
            integer(ip) :: bw, ii, kk
            bw = 0
            do ii = 1, a%nrow
                do kk = a%p(ii), a%p(ii + 1) - 1
                    bw = max(bw, abs(sys%iperm(ii) - sys%iperm(a%i(kk))))
                end do
            end do
        end function pattern_bw

        !> Spread, under perm, of the full DoFs an element's rows touch.
        function elem_bw(gg, r1, r2, s) result(bw)
            type(csr_matrix), intent(in) :: gg
            integer(ip), intent(in) :: r1, r2
            class(hbm_system), intent(in) :: s
            integer(ip) :: bw, lo, hi, rr, kk, col
            lo = huge(lo)
            hi = -huge(hi)
            do rr = r1, r2
                do kk = gg%p(rr), gg%p(rr + 1) - 1
                    col = gg%i(kk)
                    select type (s)
                    type is (hbm_condensed)
                        col = nl(col)
                    end select
                    lo = min(lo, s%iperm(col))
                    hi = max(hi, s%iperm(col))
                end do
            end do
            bw = max(hi - lo, 0)
        end function elem_bw
    end subroutine hbm_setup

    !> Forces fd(ncol, nc) = G^T f(G xd) of all contact groups, and their local Jacobians
    !> (kept in the groups) when jac is true. With carry, each group's w0 becomes the slider
    !> its closed cycle at xd starts with (the history the next point inherits).
    subroutine contact_eval(cs, plan, xd, fd, jac, info, errmsg, carry)
        type(contact_set), intent(inout) :: cs
        type(aft_plan), intent(inout) :: plan
        real(wp), intent(in) :: xd(:, :)    !! (ncol, nc) harmonics of the columns
        real(wp), intent(out) :: fd(:, :)   !! (ncol, nc) contact forces on the columns
        logical, intent(in) :: jac
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        logical, intent(in), optional :: carry
        integer(ip) :: g, e, d, row, k
        real(wp), allocatable :: wnew(:, :)
        logical :: upd
        info = FRIROM_OK
        upd = .false.
        if (present(carry)) upd = carry
        fd = 0.0_wp
        do g = 1, size(cs%grp)
            associate (gr => cs%grp(g), gg => cs%g)
                do e = 1, gr%ne
                    do d = 1, gr%ndir
                        row = gr%row0 + (e - 1)*gr%ndir + d
                        gr%x(:, d, e) = 0.0_wp
                        do k = gg%p(row), gg%p(row + 1) - 1
                            gr%x(:, d, e) = gr%x(:, d, e) + gg%x(k)*xd(gg%i(k), :)
                        end do
                    end do
                end do
                if (upd) then
                    allocate (wnew, mold=gr%w0)
                    wnew = gr%w0
                    call aft_eval(plan, gr%law, gr%x, gr%params, gr%w0, gr%f, info, errmsg, &
                                  states=gr%states, slider=wnew)
                    if (info == 0) gr%w0 = wnew
                    deallocate (wnew)
                else if (jac) then
                    call aft_eval(plan, gr%law, gr%x, gr%params, gr%w0, gr%f, info, errmsg, &
                                  jac=gr%jac, states=gr%states)
                else
                    call aft_eval(plan, gr%law, gr%x, gr%params, gr%w0, gr%f, info, errmsg, &
                                  states=gr%states)
                end if
                if (info /= 0) return
                do e = 1, gr%ne
                    do d = 1, gr%ndir
                        row = gr%row0 + (e - 1)*gr%ndir + d
                        do k = gg%p(row), gg%p(row + 1) - 1
                            fd(gg%i(k), :) = fd(gg%i(k), :) + gg%x(k)*gr%f(:, d, e)
                        end do
                    end do
                end do
            end associate
        end do
    end subroutine contact_eval

    !> Add G^T J_loc G (from the last contact_eval with jac) to a dense matrix kd, index
    !> col + ncol (c-1), or to a banded matrix kb, index c + nc (iperm(col)-1).
    subroutine contact_assemble(cs, kd, kb, iperm, info, errmsg, colmap, ldc)
        type(contact_set), intent(in) :: cs
        real(wp), intent(inout), optional :: kd(:, :)
        type(band_matrix), intent(inout), optional :: kb
        integer(ip), intent(in), optional :: iperm(:)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip), intent(in), optional :: colmap(:)  !! dense: column -> row/col index
        integer(ip), intent(in), optional :: ldc        !! dense: stride between harmonics
        integer(ip) :: g, e, d1, d2, r1, r2, k1, k2, c1, c2, ncol, nc, i1, i2, m1, m2
        real(wp) :: v
        logical :: ok
        info = FRIROM_OK
        ok = .true.
        nc = cs%nc
        ncol = cs%g%ncol
        if (present(ldc)) ncol = ldc
        do g = 1, size(cs%grp)
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
    end subroutine contact_assemble

    !> Accept a converged point: every contact group's initial slider becomes the slider of
    !> the closed cycle at y, so the following points continue from this point's contact
    !> history (a contact entering stick-all-cycle keeps the slider where it last slipped).
    !> Within one corrector w0 stays fixed, so R(y) and its Jacobian stay consistent.
    subroutine hbm_accept(this, y, lam, info, errmsg)
        class(hbm_system), intent(inout) :: this
        real(wp), intent(in) :: y(:)
        real(wp), intent(in) :: lam
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp), allocatable :: xd(:, :), fd(:, :)
        integer(ip) :: i, nc
        info = FRIROM_OK
        if (.false.) info = int(lam)
        if (size(this%cs%grp) == 0 .or. .not. this%carry) return
        nc = this%nc
        select type (this)
        type is (hbm_condensed)
            xd = reshape(y, [this%nnl, nc])
        class default
            allocate (xd(this%ndof, nc))
            do i = 1, this%ndof
                xd(i, :) = y(nc*(this%iperm(i) - 1) + 1:nc*this%iperm(i))
            end do
        end select
        allocate (fd(size(xd, 1), nc))
        call contact_eval(this%cs, this%plan, xd, fd, .false., info, errmsg, carry=.true.)
    end subroutine hbm_accept

    !> The initial sliders of all groups, (nslider, ne) per group concatenated (the layout
    !> of hbm_setup's w0); w must hold at least that many values, the rest is left alone.
    subroutine hbm_sliders(sys, w)
        class(hbm_system), intent(in) :: sys
        real(wp), intent(inout) :: w(:)
        integer(ip) :: g, k, nsl
        k = 0
        do g = 1, size(sys%cs%grp)
            associate (gr => sys%cs%grp(g))
                nsl = law_nslider(gr%law)
                if (nsl == 0) cycle
                w(k + 1:k + nsl*gr%ne) = reshape(gr%w0(1:nsl, :), [nsl*gr%ne])
                k = k + nsl*gr%ne
            end associate
        end do
    end subroutine hbm_sliders

    !> Frequency and load factor of the excitation at parameter lam.
    pure subroutine freq_load(sys, lam, w, s)
        class(hbm_system), intent(in) :: sys
        real(wp), intent(in) :: lam
        real(wp), intent(out) :: w, s
        if (sys%mode == HBM_FREQUENCY) then
            w = lam
            s = 0.0_wp
        else
            w = sys%omega_fix
            s = lam
        end if
    end subroutine freq_load

    ! ---- condensed formulation ------------------------------------------------------

    subroutine cond_init(sys, nl, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        integer(ip), intent(in) :: nl(:)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: nnl, n, stat
        info = FRIROM_OK
        nnl = size(nl)
        sys%nnl = nnl
        sys%nl = nl
        n = nnl*sys%nc
        sys%n = n
        allocate (sys%ymat(sys%ndof, nnl, 0:sys%nh), sys%ye0(sys%ndof, 0:sys%nh), &
                  sys%ye1(sys%ndof, 0:sys%nh), sys%ar(nnl, nnl, 0:sys%nh), &
                  sys%ai(nnl, nnl, 0:sys%nh), sys%kc(n, n), sys%jm(n, n), sys%ipiv(n), &
                  sys%xd(nnl, sys%nc), sys%fd(nnl, sys%nc), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'condensed: receptances/Jacobian')
            return
        end if
    end subroutine cond_init

    !> Use modal superposition for the receptances of a condensed system:
    !> H_h = Phi diag(1 / (w_r^2 - (h w)^2 + 2 i zeta_r w_r h w)) Phi^T over the given
    !> mass-normalised modes (truncated set: no residual flexibility).
    subroutine hbm_set_modes(sysc, phi, wm, zm, info, errmsg)
        class(hbm_system), intent(inout), target :: sysc  !! must be an hbm_condensed
        real(wp), intent(in) :: phi(:, :)   !! (ndof, nm)
        real(wp), intent(in) :: wm(:), zm(:) !! (nm) natural frequencies rad/s, ratios
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: nm, h
        info = FRIROM_OK
        nm = size(phi, 2)
        if (size(phi, 1) /= sysc%ndof .or. size(wm) /= nm .or. size(zm) /= nm .or. nm < 1) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'modes: phi (ndof, nm), '// &
                            'omega and zeta (nm)')
            return
        end if
        if (.not. all(abs(phi) <= huge(1.0_wp))) then
            call set_status(info, FRIROM_ERR_NONFINITE, errmsg, 'modes: phi has NaN or Inf')
            return
        end if
        call modal_store(sysc, nm, spread(wm, 2, sysc%nh + 1), spread(zm, 2, sysc%nh + 1), &
                         info, errmsg, phi=phi)
    end subroutine hbm_set_modes

    !> Modal superposition with modes of their own for every harmonic h:
    !> H_h = Psi_h diag(1 / (w_hr^2 - (h w)^2 + 2 i zeta_hr w_hr h w)) Psi_h^H. A cyclic
    !> sector under an engine-order excitation is such a system: harmonic h lives on
    !> the nodal diameter h EO mod N, with complex mode shapes of that diameter. Modes
    !> with psi = 0 pad harmonics that have fewer modes.
    subroutine hbm_set_modes_harmonic(sysc, psi, wm, zm, info, errmsg)
        class(hbm_system), intent(inout), target :: sysc  !! must be an hbm_condensed
        complex(wp), intent(in) :: psi(:, :, 0:)  !! (ndof, nm, 0:nh) mode shapes
        real(wp), intent(in) :: wm(:, 0:), zm(:, 0:) !! (nm, 0:nh) rad/s, damping ratios
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: nm
        info = FRIROM_OK
        nm = size(psi, 2)
        if (size(psi, 1) /= sysc%ndof .or. size(psi, 3) /= sysc%nh + 1 .or. nm < 1 .or. &
            any(shape(wm) /= [nm, sysc%nh + 1]) .or. any(shape(zm) /= shape(wm))) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'harmonic modes: psi (ndof, nm, '// &
                            'H+1), omega and zeta (nm, H+1)')
            return
        end if
        if (.not. all(abs(psi) <= huge(1.0_wp))) then
            call set_status(info, FRIROM_ERR_NONFINITE, errmsg, 'harmonic modes: psi has '// &
                            'NaN or Inf')
            return
        end if
        call modal_store(sysc, nm, wm, zm, info, errmsg, psi=psi)
    end subroutine hbm_set_modes_harmonic

    !> Keep the modes on the rows the solver reads (contact and output DoFs) and project
    !> both load parts on them; the modes are phi (real, the same for every harmonic) or
    !> psi (complex, per harmonic), on all DoFs.
    subroutine modal_store(sysc, nm, wm, zm, info, errmsg, phi, psi)
        class(hbm_system), intent(inout), target :: sysc
        integer(ip), intent(in) :: nm
        real(wp), intent(in) :: wm(:, 0:), zm(:, 0:)   !! (nm, 0:nh)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp), intent(in), optional :: phi(:, :)         !! (ndof, nm)
        complex(wp), intent(in), optional :: psi(:, :, 0:)  !! (ndof, nm, 0:nh)
        integer(ip) :: h, r, i, nr
        logical, allocatable :: extra(:)
        complex(wp), allocatable :: v(:), f0(:), f1(:)
        info = FRIROM_OK
        select type (sys => sysc)
        type is (hbm_condensed)
            allocate (extra(sys%ndof))
            extra = .false.
            extra(sys%outdofs) = .true.
            extra(sys%nl) = .false.
            sys%mrow = [sys%nl, pack([(i, i=1, sys%ndof)], extra)]
            nr = size(sys%mrow)
            if (allocated(sys%psi)) deallocate (sys%psi, sys%wm, sys%zm, sys%dg, sys%qf, &
                                                sys%qf1)
            allocate (sys%psi(nr, nm, 0:sys%nh), sys%wm(nm, 0:sys%nh), sys%zm(nm, 0:sys%nh), &
                      sys%dg(nm, 0:sys%nh), sys%qf(nm, 0:sys%nh), sys%qf1(nm, 0:sys%nh))
            do h = 0, sys%nh
                sys%wm(:, h) = wm(:, h)
                sys%zm(:, h) = zm(:, h)
                f0 = harm_col(sys%fe0, h)
                f1 = harm_col(sys%fe1, h)
                do r = 1, nm
                    if (present(phi)) then
                        v = cmplx(phi(:, r), 0.0_wp, wp)
                    else
                        v = psi(:, r, h)
                    end if
                    sys%psi(:, r, h) = v(sys%mrow)
                    sys%qf(r, h) = sum(conjg(v)*f0)
                    sys%qf1(r, h) = sum(conjg(v)*f1)
                end do
            end do
            if (any(sys%wm <= 0.0_wp) .or. any(sys%zm < 0.0_wp) .or. &
                .not. all(abs(sys%wm) + abs(sys%zm) <= huge(1.0_wp))) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'modes: need omega > 0 and '// &
                                'zeta >= 0, finite')
                return
            end if
            sys%modal = .true.
            sys%w_cache = -1.0_wp
        class default
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'modal superposition needs the '// &
                            'condensed formulation')
        end select
    end subroutine modal_store

    !> Complex amplitudes of harmonic h of every row of a real-harmonic array a(:, 2H+1).
    pure function harm_col(a, h) result(z)
        real(wp), intent(in) :: a(:, :)
        integer(ip), intent(in) :: h
        complex(wp) :: z(size(a, 1))
        if (h == 0) then
            z = cmplx(a(:, 1), 0.0_wp, wp)
        else
            z = cmplx(a(:, 2*h), -a(:, 2*h + 1), wp)
        end if
    end function harm_col

    !> Receptance columns at w from the modes (see hbm_set_modes), on the kept rows.
    subroutine cond_receptance_modal(sys, w)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(in) :: w
        integer(ip) :: h, j, nm, nr
        real(wp) :: hw, t0
        complex(wp), allocatable :: g(:), tmp(:, :), rows(:, :)
        t0 = wtime()
        nm = size(sys%wm, 1)
        nr = size(sys%mrow)
        allocate (g(nm), tmp(nm, sys%nnl), rows(nr, sys%nnl))
        do h = 0, sys%nh
            hw = h*w
            associate (wr => sys%wm(:, h), zr => sys%zm(:, h), ps => sys%psi(:, :, h))
                g = 1.0_wp/cmplx(wr**2 - hw**2, 2.0_wp*zr*wr*hw, wp)
                sys%dg(:, h) = -g**2*cmplx(-2.0_wp*h*hw, 2.0_wp*zr*wr*h, wp)
                do j = 1, sys%nnl
                    tmp(:, j) = g*conjg(ps(j, :))
                end do
                call zgemm('N', 'N', nr, sys%nnl, nm, (1.0_wp, 0.0_wp), ps, nr, tmp, nm, &
                           (0.0_wp, 0.0_wp), rows, nr)
                sys%ymat(sys%mrow, :, h) = rows
                sys%ye0(sys%mrow, h) = matmul(ps, g*sys%qf(:, h))
                sys%ye1(sys%mrow, h) = matmul(ps, g*sys%qf1(:, h))
            end associate
            do j = 1, sys%nnl
                sys%ar(j, :, h) = real(sys%ymat(sys%nl(j), :, h), wp)
                sys%ai(j, :, h) = aimag(sys%ymat(sys%nl(j), :, h))
            end do
        end do
        sys%w_cache = w
        sys%timers(T_REC) = sys%timers(T_REC) + wtime() - t0
    end subroutine cond_receptance_modal

    !> Receptance columns D_h^-1 P^T and D_h^-1 fe at frequency w, h = 0..H.
    subroutine cond_receptance(sys, w, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(in) :: w
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: h, i, k, j, ndof, nnl
        complex(wp), allocatable :: rhs(:, :)
        real(wp) :: hw, t0
        logical :: ok
        info = FRIROM_OK
        if (sys%modal) then
            call cond_receptance_modal(sys, w)
            return
        end if
        if (.not. allocated(sys%d%ab)) then
            call zband_init(sys%d, sys%ndof, sys%bw, sys%bw, info, errmsg)
            if (info /= 0) return
        end if
        t0 = wtime()
        ndof = sys%ndof
        nnl = sys%nnl
        ok = .true.
        allocate (rhs(ndof, nnl + 2))
        do h = 0, sys%nh
            hw = h*w
            call zband_zero(sys%d)
            do i = 1, ndof
                do k = sys%k%p(i), sys%k%p(i + 1) - 1
                    call zband_add(sys%d, sys%iperm(i), sys%iperm(sys%k%i(k)), &
                                   cmplx(sys%k%x(k), 0.0_wp, wp), ok)
                end do
                do k = sys%m%p(i), sys%m%p(i + 1) - 1
                    call zband_add(sys%d, sys%iperm(i), sys%iperm(sys%m%i(k)), &
                                   cmplx(-hw*hw*sys%m%x(k), 0.0_wp, wp), ok)
                end do
                if (h > 0) then
                    do k = sys%c%p(i), sys%c%p(i + 1) - 1
                        call zband_add(sys%d, sys%iperm(i), sys%iperm(sys%c%i(k)), &
                                       cmplx(0.0_wp, hw*sys%c%x(k), wp), ok)
                    end do
                end if
            end do
            if (.not. ok) then
                call set_status(info, FRIROM_ERR_MODEL, errmsg, 'receptance: entry outside band')
                return
            end if
            call zband_factor(sys%d, info, errmsg)
            if (info /= 0) return
            rhs = (0.0_wp, 0.0_wp)
            do j = 1, nnl
                rhs(sys%iperm(sys%nl(j)), j) = (1.0_wp, 0.0_wp)
            end do
            rhs(sys%iperm, nnl + 1) = harm_col(sys%fe0, h)
            rhs(sys%iperm, nnl + 2) = harm_col(sys%fe1, h)
            call zband_solve(sys%d, rhs, info, errmsg)
            if (info /= 0) return
            do i = 1, ndof
                sys%ymat(i, :, h) = rhs(sys%iperm(i), 1:nnl)
                sys%ye0(i, h) = rhs(sys%iperm(i), nnl + 1)
                sys%ye1(i, h) = rhs(sys%iperm(i), nnl + 2)
            end do
            do j = 1, nnl
                sys%ar(j, :, h) = real(sys%ymat(sys%nl(j), :, h), wp)
                sys%ai(j, :, h) = aimag(sys%ymat(sys%nl(j), :, h))
            end do
        end do
        sys%w_cache = w
        sys%timers(T_REC) = sys%timers(T_REC) + wtime() - t0
    end subroutine cond_receptance

    subroutine cond_eval(this, y, lam, r, rref, jac, rlam, info, errmsg)
        class(hbm_condensed), intent(inout) :: this
        real(wp), intent(in) :: y(:)
        real(wp), intent(in) :: lam
        real(wp), intent(out) :: r(:)
        real(wp), intent(out) :: rref
        logical, intent(in) :: jac
        real(wp), intent(out) :: rlam(:)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp) :: w, s, t0, nx, nxe, nhf
        integer(ip) :: nnl, nc, h, ca, cb, n, linfo
        complex(wp), allocatable :: fc(:), z(:), dz(:), rh(:), xe(:)
        info = FRIROM_OK
        nnl = this%nnl
        nc = this%nc
        n = this%n
        call freq_load(this, lam, w, s)
        if (w /= this%w_cache) then
            call cond_receptance(this, w, info, errmsg)
            if (info /= 0) return
        end if
        this%xd = reshape(y, [nnl, nc])
        t0 = wtime()
        call contact_eval(this%cs, this%plan, this%xd, this%fd, jac, info, errmsg)
        this%timers(T_AFT) = this%timers(T_AFT) + wtime() - t0
        this%timers(N_EVAL) = this%timers(N_EVAL) + 1
        if (info /= 0) return
        allocate (fc(nnl), z(this%ndof), dz(this%ndof), rh(nnl), xe(nnl))
        nxe = 0.0_wp
        nhf = 0.0_wp
        nx = norm2(y)
        do h = 0, this%nh
            fc = harm_col(this%fd, h)
            xe = this%ye0(this%nl, h) + s*this%ye1(this%nl, h)
            rh = cmplx(matmul(this%ar(:, :, h), real(fc, wp)) - &
                       matmul(this%ai(:, :, h), aimag(fc)), &
                       matmul(this%ar(:, :, h), aimag(fc)) + &
                       matmul(this%ai(:, :, h), real(fc, wp)), wp)
            nhf = nhf + sum(abs(rh)**2)
            nxe = nxe + sum(abs(xe)**2)
            rh = rh - xe
            ! dR/dlam
            if (this%mode == HBM_FREQUENCY) then
                if (h == 0) then
                    dz = (0.0_wp, 0.0_wp)
                    rh = rh + cmplx(this%xd(:, 1), 0.0_wp, wp)
                    r(1:nnl) = real(rh, wp)
                    rlam(1:nnl) = 0.0_wp
                    cycle
                end if
                if (this%modal) then
                    ! R = X - Phi_n diag(g) (Phi^T fe - Phi_n^T fc): dR/dw = -Phi_n dg q
                    associate (pn => this%psi(1:nnl, :, h))
                        xe = -matmul(pn, this%dg(:, h)*(this%qf(:, h) - &
                                                        matmul(conjg(transpose(pn)), fc)))
                    end associate
                    ca = 2*h
                    cb = 2*h + 1
                    rh = rh + cmplx(this%xd(:, ca), -this%xd(:, cb), wp)
                    r(nnl*(ca - 1) + 1:nnl*ca) = real(rh, wp)
                    r(nnl*(cb - 1) + 1:nnl*cb) = -aimag(rh)
                    rlam(nnl*(ca - 1) + 1:nnl*ca) = real(xe, wp)
                    rlam(nnl*(cb - 1) + 1:nnl*cb) = -aimag(xe)
                    cycle
                end if
                ! z = D^-1 (fe - P^T fc); dR/dw = Y^T D'(w) z, D' = i h C - 2 h^2 w M
                z = this%ye0(:, h) - matmul(this%ymat(:, :, h), fc)
                dz = (0.0_wp, 0.0_wp)
                call zcsr_add(this%c, z, dz, cmplx(0.0_wp, real(h, wp), wp))
                call zcsr_add(this%m, z, dz, cmplx(-2.0_wp*h*h*w, 0.0_wp, wp))
                xe = matmul(transpose(this%ymat(:, :, h)), dz)
            else
                xe = -this%ye1(this%nl, h)
            end if
            if (h == 0) then
                rh = rh + cmplx(this%xd(:, 1), 0.0_wp, wp)
                r(1:nnl) = real(rh, wp)
                rlam(1:nnl) = real(xe, wp)
            else
                ca = 2*h
                cb = 2*h + 1
                rh = rh + cmplx(this%xd(:, ca), -this%xd(:, cb), wp)
                r(nnl*(ca - 1) + 1:nnl*ca) = real(rh, wp)
                r(nnl*(cb - 1) + 1:nnl*cb) = -aimag(rh)
                rlam(nnl*(ca - 1) + 1:nnl*ca) = real(xe, wp)
                rlam(nnl*(cb - 1) + 1:nnl*cb) = -aimag(xe)
            end if
        end do
        rref = max(sqrt(nxe), nx, sqrt(nhf))
        if (.not. jac) return
        ! J = I + H_nn dF/dX, harmonic block by harmonic block
        t0 = wtime()
        this%kc = 0.0_wp
        call contact_assemble(this%cs, kd=this%kc, info=info, errmsg=errmsg)
        if (info /= 0) return
        this%jm = 0.0_wp
        do h = 0, this%nh
            if (h == 0) then
                call dgemm('N', 'N', nnl, n, nnl, 1.0_wp, this%ar(:, :, 0), nnl, &
                           this%kc(1, 1), n, 0.0_wp, this%jm(1, 1), n)
            else
                ca = nnl*(2*h - 1) + 1
                cb = nnl*(2*h) + 1
                ! a-rows: A Kc_a + B Kc_b ; b-rows: -B Kc_a + A Kc_b (H = A + iB)
                call dgemm('N', 'N', nnl, n, nnl, 1.0_wp, this%ar(:, :, h), nnl, &
                           this%kc(ca, 1), n, 0.0_wp, this%jm(ca, 1), n)
                call dgemm('N', 'N', nnl, n, nnl, 1.0_wp, this%ai(:, :, h), nnl, &
                           this%kc(cb, 1), n, 1.0_wp, this%jm(ca, 1), n)
                call dgemm('N', 'N', nnl, n, nnl, -1.0_wp, this%ai(:, :, h), nnl, &
                           this%kc(ca, 1), n, 0.0_wp, this%jm(cb, 1), n)
                call dgemm('N', 'N', nnl, n, nnl, 1.0_wp, this%ar(:, :, h), nnl, &
                           this%kc(cb, 1), n, 1.0_wp, this%jm(cb, 1), n)
            end if
        end do
        do h = 1, n
            this%jm(h, h) = this%jm(h, h) + 1.0_wp
        end do
        this%timers(T_ASM) = this%timers(T_ASM) + wtime() - t0
        t0 = wtime()
        call dgetrf(n, n, this%jm, n, this%ipiv, linfo)
        this%timers(T_FACT) = this%timers(T_FACT) + wtime() - t0
        this%timers(N_FACT) = this%timers(N_FACT) + 1
        if (linfo > 0) then
            call set_status(info, FRIROM_ERR_SINGULAR, errmsg, 'condensed Jacobian: dgetrf '// &
                            'zero pivot')
        else if (linfo < 0) then
            call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'dgetrf: illegal argument')
        end if
    end subroutine cond_eval

    !> y += alpha A x for complex x (A real CSR).
    pure subroutine zcsr_add(a, x, y, alpha)
        type(csr_matrix), intent(in) :: a
        complex(wp), intent(in) :: x(:)
        complex(wp), intent(inout) :: y(:)
        complex(wp), intent(in) :: alpha
        integer(ip) :: i, k
        complex(wp) :: s
        do i = 1, a%nrow
            s = (0.0_wp, 0.0_wp)
            do k = a%p(i), a%p(i + 1) - 1
                s = s + a%x(k)*x(a%i(k))
            end do
            y(i) = y(i) + alpha*s
        end do
    end subroutine zcsr_add

    subroutine cond_solve(this, b, info, errmsg)
        class(hbm_condensed), intent(inout) :: this
        real(wp), intent(inout) :: b(:, :)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: linfo
        real(wp) :: t0
        info = FRIROM_OK
        t0 = wtime()
        call dgetrs('N', this%n, size(b, 2), this%jm, this%n, this%ipiv, b, size(b, 1), linfo)
        this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
        if (linfo /= 0) call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'dgetrs failed')
    end subroutine cond_solve

    !> Eq. 9: x_o = rows o of D_h^-1 (fe - P^T fc), from the cached receptance columns.
    subroutine cond_outputs(this, y, lam, xo, info, errmsg)
        class(hbm_condensed), intent(inout) :: this
        real(wp), intent(in) :: y(:), lam
        real(wp), intent(out) :: xo(:, :)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp) :: w, s
        integer(ip) :: h, j, o
        complex(wp) :: z
        complex(wp), allocatable :: fc(:)
        info = FRIROM_OK
        call freq_load(this, lam, w, s)
        if (w /= this%w_cache) then
            call cond_receptance(this, w, info, errmsg)
            if (info /= 0) return
        end if
        this%xd = reshape(y, [this%nnl, this%nc])
        call contact_eval(this%cs, this%plan, this%xd, this%fd, .false., info, errmsg)
        if (info /= 0) return
        allocate (fc(this%nnl))
        do h = 0, this%nh
            fc = harm_col(this%fd, h)
            do j = 1, size(this%outdofs)
                o = this%outdofs(j)
                z = this%ye0(o, h) + s*this%ye1(o, h) - sum(this%ymat(o, :, h)*fc)
                if (h == 0) then
                    xo(j, 1) = real(z, wp)
                else
                    xo(j, 2*h) = real(z, wp)
                    xo(j, 2*h + 1) = -aimag(z)
                end if
            end do
        end do
    end subroutine cond_outputs

    ! ---- full banded formulation ----------------------------------------------------

    subroutine full_init(sys, info, errmsg)
        type(hbm_full), intent(inout) :: sys
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: kl
        sys%n = sys%ndof*sys%nc
        kl = min(sys%nc*(sys%bw + 1) - 1, sys%n - 1)
        allocate (sys%xd(sys%ndof, sys%nc), sys%fd(sys%ndof, sys%nc), sys%rd(sys%ndof, sys%nc))
        call band_init(sys%jb, sys%n, kl, kl, info, errmsg)
    end subroutine full_init

    subroutine full_eval(this, y, lam, r, rref, jac, rlam, info, errmsg)
        class(hbm_full), intent(inout) :: this
        real(wp), intent(in) :: y(:)
        real(wp), intent(in) :: lam
        real(wp), intent(out) :: r(:)
        real(wp), intent(out) :: rref
        logical, intent(in) :: jac
        real(wp), intent(out) :: rlam(:)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp) :: w, s, t0, hw, nfe, ndx
        integer(ip) :: nc, i, h, ca, cb, k, ii, jj
        logical :: ok
        real(wp), allocatable :: dl(:, :)
        info = FRIROM_OK
        nc = this%nc
        call freq_load(this, lam, w, s)
        do i = 1, this%ndof
            this%xd(i, :) = y(nc*(this%iperm(i) - 1) + 1:nc*this%iperm(i))
        end do
        t0 = wtime()
        call contact_eval(this%cs, this%plan, this%xd, this%fd, jac, info, errmsg)
        this%timers(T_AFT) = this%timers(T_AFT) + wtime() - t0
        this%timers(N_EVAL) = this%timers(N_EVAL) + 1
        if (info /= 0) return
        ! D X, harmonic by harmonic
        allocate (dl(this%ndof, nc))
        this%rd = 0.0_wp
        dl = 0.0_wp
        call csr_matvec_add(this%k, this%xd(:, 1), this%rd(:, 1), 1.0_wp)
        do h = 1, this%nh
            hw = h*w
            ca = 2*h
            cb = 2*h + 1
            call csr_matvec_add(this%k, this%xd(:, ca), this%rd(:, ca), 1.0_wp)
            call csr_matvec_add(this%k, this%xd(:, cb), this%rd(:, cb), 1.0_wp)
            call csr_matvec_add(this%m, this%xd(:, ca), this%rd(:, ca), -hw*hw)
            call csr_matvec_add(this%m, this%xd(:, cb), this%rd(:, cb), -hw*hw)
            call csr_matvec_add(this%c, this%xd(:, cb), this%rd(:, ca), hw)
            call csr_matvec_add(this%c, this%xd(:, ca), this%rd(:, cb), -hw)
            if (this%mode == HBM_FREQUENCY) then
                call csr_matvec_add(this%m, this%xd(:, ca), dl(:, ca), -2.0_wp*h*hw)
                call csr_matvec_add(this%m, this%xd(:, cb), dl(:, cb), -2.0_wp*h*hw)
                call csr_matvec_add(this%c, this%xd(:, cb), dl(:, ca), real(h, wp))
                call csr_matvec_add(this%c, this%xd(:, ca), dl(:, cb), -real(h, wp))
            end if
        end do
        ndx = norm2(this%rd)
        nfe = norm2(this%fe0 + s*this%fe1)
        rref = max(nfe, ndx, norm2(this%fd))
        this%rd = this%rd + this%fd - this%fe0 - s*this%fe1
        if (this%mode == HBM_LOAD) dl = -this%fe1
        do i = 1, this%ndof
            r(nc*(this%iperm(i) - 1) + 1:nc*this%iperm(i)) = this%rd(i, :)
            rlam(nc*(this%iperm(i) - 1) + 1:nc*this%iperm(i)) = dl(i, :)
        end do
        if (.not. jac) return
        t0 = wtime()
        ok = .true.
        call band_zero(this%jb)
        do i = 1, this%ndof
            ii = nc*(this%iperm(i) - 1)
            do k = this%k%p(i), this%k%p(i + 1) - 1
                jj = nc*(this%iperm(this%k%i(k)) - 1)
                do h = 1, nc
                    call band_add(this%jb, ii + h, jj + h, this%k%x(k), ok)
                end do
            end do
            do k = this%m%p(i), this%m%p(i + 1) - 1
                jj = nc*(this%iperm(this%m%i(k)) - 1)
                do h = 1, this%nh
                    hw = h*w
                    call band_add(this%jb, ii + 2*h, jj + 2*h, -hw*hw*this%m%x(k), ok)
                    call band_add(this%jb, ii + 2*h + 1, jj + 2*h + 1, -hw*hw*this%m%x(k), ok)
                end do
            end do
            do k = this%c%p(i), this%c%p(i + 1) - 1
                jj = nc*(this%iperm(this%c%i(k)) - 1)
                do h = 1, this%nh
                    hw = h*w
                    call band_add(this%jb, ii + 2*h, jj + 2*h + 1, hw*this%c%x(k), ok)
                    call band_add(this%jb, ii + 2*h + 1, jj + 2*h, -hw*this%c%x(k), ok)
                end do
            end do
        end do
        if (.not. ok) then
            call set_status(info, FRIROM_ERR_MODEL, errmsg, 'full Jacobian: entry outside band')
            return
        end if
        call contact_assemble(this%cs, kb=this%jb, iperm=this%iperm, info=info, errmsg=errmsg)
        this%timers(T_ASM) = this%timers(T_ASM) + wtime() - t0
        if (info /= 0) return
        t0 = wtime()
        call band_factor(this%jb, info, errmsg)
        this%timers(T_FACT) = this%timers(T_FACT) + wtime() - t0
        this%timers(N_FACT) = this%timers(N_FACT) + 1
    end subroutine full_eval

    subroutine full_solve(this, b, info, errmsg)
        class(hbm_full), intent(inout) :: this
        real(wp), intent(inout) :: b(:, :)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp) :: t0
        t0 = wtime()
        call band_solve(this%jb, b, info, errmsg)
        this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
    end subroutine full_solve

    subroutine full_outputs(this, y, lam, xo, info, errmsg)
        class(hbm_full), intent(inout) :: this
        real(wp), intent(in) :: y(:), lam
        real(wp), intent(out) :: xo(:, :)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: j, nc, p
        info = FRIROM_OK
        nc = this%nc
        do j = 1, size(this%outdofs)
            p = this%iperm(this%outdofs(j))
            xo(j, :) = y(nc*(p - 1) + 1:nc*p)
        end do
        if (.false.) xo(1, 1) = lam
        if (.false.) errmsg = ''
    end subroutine full_outputs


    ! ---- stability --------------------------------------------------------------------

    !> Floquet exponents of the periodic solution y at lam by Hill's method: the quadratic
    !> eigenproblem (J + s D1 + s^2 M) p = 0 over all DoFs x harmonics (J = dR/dX of the
    !> full equations, D1 = C + 2 M d/dt), linearised to a 2n standard eigenproblem (dense,
    !> dgeev). Of the 2n(2H+1) eigenvalues, the 2 ndof with the smallest |Im s| are the
    !> physically meaningful exponents (the others repeat them shifted by i h w).
    !> maxre: their largest real part; the solution is stable when maxre <= 0.
    subroutine hbm_hill(sys, y, lam, expo, maxre, info, errmsg)
        class(hbm_system), intent(inout) :: sys
        real(wp), intent(in) :: y(:), lam
        complex(wp), intent(out) :: expo(:)   !! (2 ndof) selected exponents, 1/s
        real(wp), intent(out) :: maxre        !! max real part of expo, 1/s
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip), parameter :: NMAX = 4000
        real(wp), allocatable :: jm(:, :), d1(:, :), md(:, :), a(:, :), wr(:), wi(:), &
                                 work(:), xd(:, :), fd(:, :), key(:)
        real(wp) :: w, s, hw, vl(1, 1), vr(1, 1), wq(1)
        integer(ip), allocatable :: colmap(:), idx(:)
        integer(ip) :: nd, nc, n, i, k, j, h, c, linfo, lwork, stat, m, t
        info = FRIROM_OK
        nd = sys%ndof
        nc = sys%nc
        n = nd*nc
        if (size(expo) /= 2*nd) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'hbm_hill: expo needs 2 ndof')
            return
        end if
        if (2*n > NMAX) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'Hill stability: 2 ndof (2H+1) '// &
                            'exceeds 4000 (dense eigen-solve); reduce the model or H')
            return
        end if
        call freq_load(sys, lam, w, s)
        allocate (jm(n, n), d1(n, n), md(nd, nd), a(2*n, 2*n), wr(2*n), wi(2*n), key(2*n), &
                  idx(2*n), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'Hill matrices')
            return
        end if
        ! contact Jacobians at the solution
        select type (sys)
        type is (hbm_condensed)
            xd = reshape(y, [sys%nnl, nc])
            colmap = sys%nl
        class default
            allocate (xd(nd, nc))
            do i = 1, nd
                xd(i, :) = y(nc*(sys%iperm(i) - 1) + 1:nc*sys%iperm(i))
            end do
            colmap = [(i, i = 1, nd)]
        end select
        allocate (fd(size(xd, 1), nc))
        call contact_eval(sys%cs, sys%plan, xd, fd, .true., info, errmsg)
        if (info /= 0) return
        jm = 0.0_wp
        d1 = 0.0_wp
        md = 0.0_wp
        call contact_assemble(sys%cs, kd=jm, info=info, errmsg=errmsg, colmap=colmap, ldc=nd)
        if (info /= 0) return
        do i = 1, nd
            do k = sys%k%p(i), sys%k%p(i + 1) - 1
                j = sys%k%i(k)
                do c = 1, nc
                    jm(i + nd*(c - 1), j + nd*(c - 1)) = jm(i + nd*(c - 1), j + nd*(c - 1)) + &
                                                         sys%k%x(k)
                end do
            end do
            do k = sys%m%p(i), sys%m%p(i + 1) - 1
                j = sys%m%i(k)
                md(i, j) = md(i, j) + sys%m%x(k)
                do h = 1, sys%nh
                    hw = h*w
                    jm(i + nd*(2*h - 1), j + nd*(2*h - 1)) = &
                        jm(i + nd*(2*h - 1), j + nd*(2*h - 1)) - hw*hw*sys%m%x(k)
                    jm(i + nd*(2*h), j + nd*(2*h)) = jm(i + nd*(2*h), j + nd*(2*h)) - &
                                                     hw*hw*sys%m%x(k)
                    d1(i + nd*(2*h - 1), j + nd*(2*h)) = d1(i + nd*(2*h - 1), j + nd*(2*h)) + &
                                                         2*hw*sys%m%x(k)
                    d1(i + nd*(2*h), j + nd*(2*h - 1)) = d1(i + nd*(2*h), j + nd*(2*h - 1)) - &
                                                         2*hw*sys%m%x(k)
                end do
            end do
            do k = sys%c%p(i), sys%c%p(i + 1) - 1
                j = sys%c%i(k)
                do c = 1, nc
                    d1(i + nd*(c - 1), j + nd*(c - 1)) = d1(i + nd*(c - 1), j + nd*(c - 1)) + &
                                                         sys%c%x(k)
                end do
                do h = 1, sys%nh
                    hw = h*w
                    jm(i + nd*(2*h - 1), j + nd*(2*h)) = jm(i + nd*(2*h - 1), j + nd*(2*h)) + &
                                                         hw*sys%c%x(k)
                    jm(i + nd*(2*h), j + nd*(2*h - 1)) = jm(i + nd*(2*h), j + nd*(2*h - 1)) - &
                                                         hw*sys%c%x(k)
                end do
            end do
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
        call dgeev('N', 'N', 2*n, a, 2*n, wr, wi, vl, 1, vr, 1, wq, -1, linfo)
        lwork = int(wq(1))
        allocate (work(lwork))
        call dgeev('N', 'N', 2*n, a, 2*n, wr, wi, vl, 1, vr, 1, work, lwork, linfo)
        if (linfo /= 0) then
            call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'Hill: dgeev did not converge')
            return
        end if
        ! the 2 ndof exponents with the smallest |Im s| (selection sort, m is small)
        key = abs(wi)
        idx = [(i, i = 1, 2*n)]
        m = 2*nd
        do i = 1, m
            k = i
            do j = i + 1, 2*n
                if (key(idx(j)) < key(idx(k))) k = j
            end do
            t = idx(i)
            idx(i) = idx(k)
            idx(k) = t
            expo(i) = cmplx(wr(idx(i)), wi(idx(i)), wp)
        end do
        maxre = maxval(real(expo, wp))
    end subroutine hbm_hill

    ! ---- driver ---------------------------------------------------------------------

    !> Solve and continue: start_mode 0 solves at fixed lam from y then continues,
    !> 1 continues from the converged point (y, lam) with tangent t, 2 only solves at
    !> fixed lam. Each point stores y, lam, tangent, Newton iterations, output harmonics
    !> and contact state fractions. On a failure every point already made is kept (npts).
    subroutine hbm_run(sys, start_mode, y, lam, t, ds, lam_lo, opts, ys, lams, tans, iters, &
                       xo, states, npts, finished, info, errmsg, hill_re, sliders)
        class(hbm_system), intent(inout) :: sys
        integer(ip), intent(in) :: start_mode
        real(wp), intent(inout) :: y(:), lam, t(:), ds
        real(wp), intent(in) :: lam_lo
        type(cont_options), intent(in) :: opts
        real(wp), intent(out) :: ys(:, :)        !! (n, maxpts)
        real(wp), intent(out) :: lams(:)         !! (maxpts)
        real(wp), intent(out) :: tans(:, :)      !! (n+1, maxpts)
        integer(ip), intent(out) :: iters(:)     !! (maxpts)
        real(wp), intent(out) :: xo(:, :, :)     !! (nout, nc, maxpts)
        real(wp), intent(out) :: states(:, :, :) !! (3, ne_total, maxpts)
        integer(ip), intent(out) :: npts
        logical, intent(out) :: finished
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp), intent(out), optional :: hill_re(:)  !! (maxpts) max Re of the Floquet
                                                        !! exponents (only when present)
        real(wp), intent(inout), optional :: sliders(:, :)  !! (nw, maxpts) the contact
                                !! history each point leaves (hbm_sliders layout)
        type(cont_options) :: o1
        real(wp), allocatable :: zero(:), yb(:, :), lb(:), tb(:, :), t0(:)
        integer(ip) :: it, n1, maxpts, ib(1)
        logical :: have_fact
        info = FRIROM_OK
        npts = 0
        finished = .false.
        maxpts = size(lams)
        if (size(y) /= sys%n .or. size(t) /= sys%n + 1 .or. size(ys, 1) /= sys%n .or. &
            size(ys, 2) /= maxpts .or. size(tans, 1) /= sys%n + 1 .or. &
            size(xo, 1) /= size(sys%outdofs) .or. size(xo, 2) /= sys%nc .or. maxpts < 1) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'hbm_run: array sizes')
            return
        end if
        allocate (zero(sys%n), yb(sys%n, 1), lb(1), tb(sys%n + 1, 1), t0(sys%n + 1))
        zero = 0.0_wp
        if (start_mode /= 1) then
            have_fact = .false.
            call newton_correct(sys, y, lam, y, lam, zero, 1.0_wp, opts, it, info, errmsg, &
                                have_fact)
            if (info /= 0) return
            call sys%accept(y, lam, info, errmsg)
            if (info /= 0) return
            t0 = 0.0_wp
            call cont_tangent(sys, y, lam, opts, t0, sign(1.0_wp, opts%lam_end - lam), t, &
                              info, errmsg)
            if (info /= 0) return
            call store(it)
            if (info /= 0) return
            if (start_mode == 2) then
                finished = .true.
                return
            end if
        end if
        o1 = opts
        o1%max_points = 1
        have_fact = start_mode /= 1   ! cont_tangent left J at the first point
        do while (npts < maxpts)
            call cont_run(sys, y, lam, t, ds, lam_lo, o1, yb, lb, tb, ib, n1, finished, &
                          info, errmsg, have_fact)
            if (n1 == 1) then
                it = info
                call store(ib(1))
                if (it /= 0) info = it
            end if
            if (info /= 0 .or. finished) return
        end do

    contains

        subroutine store(itn)
            integer(ip), intent(in) :: itn
            integer(ip) :: g, e0
            complex(wp), allocatable :: ex(:)
            npts = npts + 1
            ys(:, npts) = y
            lams(npts) = lam
            tans(:, npts) = t
            iters(npts) = itn
            if (present(sliders)) call hbm_sliders(sys, sliders(:, npts))
            call sys%outputs(y, lam, xo(:, :, npts), info, errmsg)
            if (info /= 0) return
            if (present(hill_re)) then
                allocate (ex(2*sys%ndof))
                call hbm_hill(sys, y, lam, ex, hill_re(npts), info, errmsg)
                if (info /= 0) return
            end if
            e0 = 0
            do g = 1, size(sys%cs%grp)
                states(:, e0 + 1:e0 + sys%cs%grp(g)%ne, npts) = sys%cs%grp(g)%states
                e0 = e0 + sys%cs%grp(g)%ne
            end do
        end subroutine store
    end subroutine hbm_run
end module frirom_hbm
