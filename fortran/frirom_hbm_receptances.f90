!> Receptances of frirom_hbm's condensed formulation, R_h = T D_h^-1 T^T and T D_h^-1 fe
!> at a frequency w: from modes (hbm_set_modes: the same real modes for every harmonic,
!> all of them for an exact dense reduced model; hbm_set_modes_harmonic: complex modes
!> per harmonic, a cyclic sector), kept on the rows T and the outputs so that a residual
!> costs products with T Phi and R_h is formed only for a Jacobian; or from a factorisation
!> of D_h = K + i h w C - (h w)^2 M per harmonic, banded (RCM order) or sparse (MUMPS).
submodule (frirom_hbm) frirom_hbm_receptances
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_PARAM, FRIROM_ERR_ALLOC, &
                             FRIROM_ERR_MODEL, FRIROM_ERR_NONFINITE, set_status, failed
    use frirom_banded, only: zband_init, zband_zero, zband_add, zband_factor, zband_solve
    use frirom_zsparse, only: zsparse_solve
    implicit none

contains

    module procedure hbm_set_modes
        integer(ip) :: nm
        info = FRIROM_OK
        nm = size(phi, 2)
        if (failed(size(phi, 1) /= sysc%ndof .or. size(wm) /= nm .or. size(zm) /= nm .or. &
                   nm < 1, info, FRIROM_ERR_SIZE, errmsg, 'modes: phi (ndof, nm), omega '// &
                   'and zeta (nm)')) return
        if (failed(.not. all(abs(phi) <= huge(1.0_wp)), info, FRIROM_ERR_NONFINITE, errmsg, &
                   'modes: phi has NaN or Inf')) return
        call modal_store(sysc, nm, spread(wm, 2, sysc%nh + 1), spread(zm, 2, sysc%nh + 1), &
                         info, errmsg, phi=phi)
    end procedure hbm_set_modes

    module procedure hbm_set_modes_harmonic
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
    end procedure hbm_set_modes_harmonic

    !> Keep the modes on the rows the solver reads, T (rows 1..nnl) and the output DoFs
    !> (rows nnl+1..), and project both load parts on them; the modes are phi (real, the
    !> same for every harmonic) or psi (complex, per harmonic), on all DoFs.
    subroutine modal_store(sysc, nm, wm, zm, info, errmsg, phi, psi)
        class(hbm_system), intent(inout), target :: sysc
        integer(ip), intent(in) :: nm
        real(wp), intent(in) :: wm(:, 0:), zm(:, 0:)   !! (nm, 0:nh)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp), intent(in), optional :: phi(:, :)         !! (ndof, nm)
        complex(wp), intent(in), optional :: psi(:, :, 0:)  !! (ndof, nm, 0:nh)
        integer(ip) :: h, r, nr, nu, stat, nld
        integer(ip), allocatable :: ld(:)
        real(wp), allocatable :: fr(:, :), q(:, :)
        info = FRIROM_OK
        ! checked before the system's current modes are given up
        if (any(wm <= 0.0_wp) .or. any(zm < 0.0_wp) .or. &
            .not. all(abs(wm) + abs(zm) <= huge(1.0_wp))) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'modes: need omega > 0 and '// &
                            'zeta >= 0, finite')
            return
        end if
        select type (sys => sysc)
        type is (hbm_condensed)
            nu = sys%nnl
            nr = nu + size(sys%outdofs)
            if (allocated(sys%phr)) deallocate (sys%phr)
            if (allocated(sys%prow)) deallocate (sys%prow)
            if (allocated(sys%psi)) deallocate (sys%psi)
            if (allocated(sys%wm)) deallocate (sys%wm, sys%zm, sys%g, sys%dg, sys%qf, sys%qf1)
            sys%gm_worth = 0.0_wp     ! gm_cost depends on the number of modes
            sys%nrc = -1.0_wp         ! so does R_0
            allocate (sys%wm(nm, 0:sys%nh), sys%zm(nm, 0:sys%nh), sys%g(nm, 0:sys%nh), &
                      sys%dg(nm, 0:sys%nh), sys%qf(nm, 0:sys%nh), sys%qf1(nm, 0:sys%nh), &
                      stat=stat)
            if (stat == 0) then
                if (present(phi)) then
                    allocate (sys%phr(nr, nm), fr(sys%ndof, 4*(sys%nh + 1)), &
                              q(nm, 4*(sys%nh + 1)), stat=stat)
                else
                    allocate (sys%psi(nr, nm, 0:sys%nh), stat=stat)
                end if
            end if
            if (failed(stat /= 0, info, FRIROM_ERR_ALLOC, errmsg, 'modes: rows of the modes')) &
                return
            sys%wm = wm
            sys%zm = zm
            if (present(phi)) then
                ! rows T phi and phi(outdofs); q = phi^T [fe0_h, fe1_h] (Re, Im) in one product
                sys%phr(1:nu, :) = 0.0_wp
                do r = 1, nm
                    call csr_matvec_add(sys%t, phi(:, r), sys%phr(1:nu, r), 1.0_wp)
                end do
                sys%phr(nu + 1:, :) = phi(sys%outdofs, :)
                do h = 0, sys%nh
                    fr(:, 4*h + 1) = real(harm_col(sys%fe0, h), wp)
                    fr(:, 4*h + 2) = aimag(harm_col(sys%fe0, h))
                    fr(:, 4*h + 3) = real(harm_col(sys%fe1, h), wp)
                    fr(:, 4*h + 4) = aimag(harm_col(sys%fe1, h))
                end do
                ! over the loaded DoFs only (the others' terms are exact zeros; a few per cent
                ! of a reduced model's DoFs are loaded)
                ld = pack([(r, r=1, sys%ndof)], any(fr /= 0.0_wp, dim=2))
                nld = size(ld)
                if (nld == 0) then
                    q = 0.0_wp
                else
                    call dgemm('T', 'N', nm, 4*(sys%nh + 1), nld, 1.0_wp, phi(ld, :), nld, &
                               fr(ld, :), nld, 0.0_wp, q, nm)
                end if
                do h = 0, sys%nh
                    sys%qf(:, h) = cmplx(q(:, 4*h + 1), q(:, 4*h + 2), wp)
                    sys%qf1(:, h) = cmplx(q(:, 4*h + 3), q(:, 4*h + 4), wp)
                end do
            else
                do h = 0, sys%nh
                    do r = 1, nm
                        sys%psi(1:nu, r, h) = (0.0_wp, 0.0_wp)
                        call csr_matvec_add(sys%t, psi(:, r, h), sys%psi(1:nu, r, h), &
                                            (1.0_wp, 0.0_wp))
                        sys%psi(nu + 1:, r, h) = psi(sys%outdofs, r, h)
                        sys%qf(r, h) = sum(conjg(psi(:, r, h))*harm_col(sys%fe0, h))
                        sys%qf1(r, h) = sum(conjg(psi(:, r, h))*harm_col(sys%fe1, h))
                    end do
                end do
            end if
            sys%modal = .true.
            sys%w_cache = -1.0_wp
            sys%w_rmat = -1.0_wp
        class default
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'modal superposition needs the '// &
                            'condensed formulation')
        end select
    end subroutine modal_store

    !> Complex amplitudes of harmonic h of every row of a real-harmonic array a(:, 2H+1).
    pure module function harm_col(a, h) result(z)
        real(wp), intent(in) :: a(:, :)
        integer(ip), intent(in) :: h
        complex(wp) :: z(size(a, 1))
        if (h == 0) then
            z = cmplx(a(:, 1), 0.0_wp, wp)
        else
            z = cmplx(a(:, 2*h), -a(:, 2*h + 1), wp)
        end if
    end function harm_col

    !> Set harmonic h of every row of a real-harmonic array a(:, 2H+1) from its complex
    !> amplitudes z (the inverse of harm_col).
    pure module subroutine harm_set(a, h, z)
        real(wp), intent(inout) :: a(:, :)
        integer(ip), intent(in) :: h
        complex(wp), intent(in) :: z(:)
        if (h == 0) then
            a(:, 1) = real(z, wp)
        else
            a(:, 2*h) = real(z, wp)
            a(:, 2*h + 1) = -aimag(z)
        end if
    end subroutine harm_set

    !> The modal factors g_r = 1/(w_r^2 - (h w)^2 + 2 i zeta_r w_r h w) of every harmonic
    !> at w and their derivatives dg_r/dw (the modal route needs nothing else per w).
    subroutine modal_factors(sys, w)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(in) :: w
        integer(ip) :: h
        real(wp) :: hw
        do h = 0, sys%nh
            hw = h*w
            associate (wr => sys%wm(:, h), zr => sys%zm(:, h))
                sys%g(:, h) = 1.0_wp/cmplx(wr**2 - hw**2, 2.0_wp*zr*wr*hw, wp)
                sys%dg(:, h) = -sys%g(:, h)**2*cmplx(-2.0_wp*h*hw, 2.0_wp*zr*wr*h, wp)
            end associate
        end do
    end subroutine modal_factors

    !> Modal route: b(:, k) = A_h x(:, k) on the mode rows lo..hi (A_h: phr or psi(:, :, h)).
    module subroutine modal_apply(sys, h, lo, hi, x, b)
        type(hbm_condensed), intent(in) :: sys
        integer(ip), intent(in) :: h, lo, hi
        complex(wp), intent(in) :: x(:, :)     !! (nm, k)
        complex(wp), intent(out) :: b(:, :)    !! (hi-lo+1, k)
        real(wp), allocatable :: xr(:, :), br(:, :)
        integer(ip) :: nm, nb, k
        nm = size(x, 1)
        k = size(x, 2)
        nb = hi - lo + 1
        if (nb < 1) return
        if (allocated(sys%phr)) then
            allocate (xr(nm, 2*k), br(nb, 2*k))
            xr(:, 1:k) = real(x, wp)
            xr(:, k + 1:) = aimag(x)
            call dgemm('N', 'N', nb, 2*k, nm, 1.0_wp, sys%phr(lo, 1), size(sys%phr, 1), xr, &
                       nm, 0.0_wp, br, nb)
            b = cmplx(br(:, 1:k), br(:, k + 1:), wp)
        else
            call zgemm('N', 'N', nb, k, nm, (1.0_wp, 0.0_wp), sys%psi(lo, 1, h), &
                       size(sys%psi, 1), x, nm, (0.0_wp, 0.0_wp), b, nb)
        end if
    end subroutine modal_apply

    !> Modal route: v = A_h^H f over the rows T (1..nnl).
    module subroutine modal_project(sys, h, f, v)
        type(hbm_condensed), intent(in) :: sys
        integer(ip), intent(in) :: h
        complex(wp), intent(in) :: f(:)        !! (nnl)
        complex(wp), intent(out) :: v(:)       !! (nm)
        real(wp), allocatable :: fr(:, :), vr(:, :)
        integer(ip) :: nu, nm
        nu = sys%nnl
        nm = size(v)
        if (allocated(sys%phr)) then
            allocate (fr(nu, 2), vr(nm, 2))
            fr(:, 1) = real(f, wp)
            fr(:, 2) = aimag(f)
            call dgemm('T', 'N', nm, 2, nu, 1.0_wp, sys%phr, size(sys%phr, 1), fr, nu, 0.0_wp, &
                       vr, nm)
            v = cmplx(vr(:, 1), vr(:, 2), wp)
        else
            call zgemm('C', 'N', nm, 1, nu, (1.0_wp, 0.0_wp), sys%psi(1, 1, h), &
                       size(sys%psi, 1), f, nu, (0.0_wp, 0.0_wp), v, nm)
        end if
    end subroutine modal_project

    !> Modal route: R_h = A_h diag(g_h) A_h^H (ar + i ai) at the Jacobian's w. Real modes:
    !> A diag(Re g) A^T and A diag(Im g) A^T, symmetric, each as the difference of two
    !> rank-k updates over the modes with positive and negative factors (dsyrk).
    module subroutine modal_rmat(sys)
        type(hbm_condensed), intent(inout) :: sys
        integer(ip) :: h, nu, nm, j, part
        real(wp), allocatable :: b(:, :), d(:)
        complex(wp), allocatable :: tmp(:, :), rz(:, :)
        real(wp) :: t0
        if (sys%w_rmat == sys%wj) return
        t0 = wtime()
        nu = sys%nnl
        nm = size(sys%g, 1)
        if (allocated(sys%phr)) then
            allocate (b(nu, nm), d(nm))
            do h = 0, sys%nh
                do part = 1, merge(1, 2, h == 0)
                    if (part == 1) then
                        d = real(sys%gj(:, h), wp)
                    else
                        d = aimag(sys%gj(:, h))
                    end if
                    if (part == 1) then
                        call sym_scaled(sys%phr, d, b, sys%ar(:, :, h))
                    else
                        call sym_scaled(sys%phr, d, b, sys%ai(:, :, h))
                    end if
                end do
                if (h == 0) sys%ai(:, :, 0) = 0.0_wp
            end do
        else
            allocate (tmp(nm, nu), rz(nu, nu))
            do h = 0, sys%nh
                associate (ps => sys%psi(1:nu, :, h))
                    do j = 1, nu
                        tmp(:, j) = sys%gj(:, h)*conjg(ps(j, :))
                    end do
                    call zgemm('N', 'N', nu, nu, nm, (1.0_wp, 0.0_wp), sys%psi(1, 1, h), &
                               size(sys%psi, 1), tmp, nm, (0.0_wp, 0.0_wp), rz, nu)
                end associate
                sys%ar(:, :, h) = real(rz, wp)
                sys%ai(:, :, h) = aimag(rz)
            end do
        end if
        sys%w_rmat = sys%wj
        sys%timers(T_REC) = sys%timers(T_REC) + wtime() - t0

    contains

        !> c = A(1:nu, :) diag(d) A(1:nu, :)^T, both triangles, by two dsyrk.
        subroutine sym_scaled(a, d, b, c)
            real(wp), intent(in) :: a(:, :), d(:)
            real(wp), intent(inout) :: b(:, :)
            real(wp), intent(out) :: c(:, :)
            integer(ip) :: r, kp, km, i
            kp = 0
            km = 0
            do r = 1, size(d)
                if (d(r) > 0.0_wp) then
                    kp = kp + 1
                    b(:, kp) = sqrt(d(r))*a(1:nu, r)
                else if (d(r) < 0.0_wp) then
                    km = km + 1
                    b(:, size(d) + 1 - km) = sqrt(-d(r))*a(1:nu, r)
                end if
            end do
            c = 0.0_wp
            if (kp > 0) call dsyrk('U', 'N', nu, kp, 1.0_wp, b, nu, 0.0_wp, c, nu)
            if (km > 0) call dsyrk('U', 'N', nu, km, -1.0_wp, b(:, size(d) + 1 - km:), nu, &
                                   1.0_wp, c, nu)
            do i = 1, nu
                c(i + 1:nu, i) = c(i, i + 1:nu)
            end do
        end subroutine sym_scaled
    end subroutine modal_rmat

    !> Receptances at frequency w: modal factors, or (banded route) D_h^-1 T^T, D_h^-1 fe,
    !> R_h = T D_h^-1 T^T and T D_h^-1 fe; cached for w.
    module subroutine cond_receptance(sys, w, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(in) :: w
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: h, j, k, h0
        real(wp) :: t0
        complex(wp), allocatable :: row(:)
        info = FRIROM_OK
        t0 = wtime()
        if (sys%modal) then
            call modal_factors(sys, w)
        else
            ! harmonic 0 (D_0 = K) does not depend on w: made once (w_cache < 0: never)
            h0 = merge(1_ip, 0_ip, sys%w_cache >= 0.0_wp .and. .not. sys%sparse_lu)
            call receptance_banded(sys, w, h0, info, errmsg)
            if (info /= 0) return
            allocate (row(sys%nnl))
            do h = h0, sys%nh
                do j = 1, sys%nnl
                    row = (0.0_wp, 0.0_wp)
                    sys%tye0(j, h) = (0.0_wp, 0.0_wp)
                    sys%tye1(j, h) = (0.0_wp, 0.0_wp)
                    do k = sys%t%p(j), sys%t%p(j + 1) - 1
                        row = row + sys%t%x(k)*sys%ymat(sys%t%i(k), :, h)
                        sys%tye0(j, h) = sys%tye0(j, h) + sys%t%x(k)*sys%ye0(sys%t%i(k), h)
                        sys%tye1(j, h) = sys%tye1(j, h) + sys%t%x(k)*sys%ye1(sys%t%i(k), h)
                    end do
                    sys%ar(j, :, h) = real(row, wp)
                    sys%ai(j, :, h) = aimag(row)
                end do
            end do
            sys%w_rmat = w
        end if
        sys%w_cache = w
        sys%timers(T_REC) = sys%timers(T_REC) + wtime() - t0
    end subroutine cond_receptance

    !> Receptance columns D_h^-1 T^T and D_h^-1 fe at frequency w from a banded LU of
    !> D_h = K + i h w C - (h w)^2 M per harmonic h0..H (those below h0 are kept).
    subroutine receptance_banded(sys, w, h0, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(in) :: w
        integer(ip), intent(in) :: h0
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: h, i, k, j, ndof, nnl, stat
        complex(wp), allocatable :: rhs(:, :)
        real(wp) :: hw
        info = FRIROM_OK
        ndof = sys%ndof
        nnl = sys%nnl
        if (.not. allocated(sys%ymat)) then
            allocate (sys%ymat(ndof, nnl, 0:sys%nh), stat=stat)
            if (stat /= 0) then
                call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'condensed: receptance columns')
                return
            end if
        end if
        if (sys%sparse_lu) then
            call receptance_sparse(sys, w, info, errmsg)
            return
        end if
        if (.not. allocated(sys%d%ab)) then
            call zband_init(sys%d, sys%ndof, sys%bw, sys%bw, info, errmsg)
            if (info /= 0) return
        end if
        if (.not. allocated(sys%dband)) then
            call band_layout(sys, info, errmsg)
            if (info /= 0) return
        end if
        allocate (rhs(ndof, nnl + 2))
        do h = h0, sys%nh
            hw = h*w
            sys%d%ab = cmplx(sys%dband(:, :, 1) - hw*hw*sys%dband(:, :, 2), &
                             hw*sys%dband(:, :, 3), wp)
            call zband_factor(sys%d, info, errmsg)
            if (info /= 0) return
            rhs = (0.0_wp, 0.0_wp)
            do j = 1, nnl
                do k = sys%t%p(j), sys%t%p(j + 1) - 1
                    rhs(sys%iperm(sys%t%i(k)), j) = rhs(sys%iperm(sys%t%i(k)), j) + sys%t%x(k)
                end do
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
        end do
    end subroutine receptance_banded

    !> K, M and C (sys%dband(:, :, 1:3)) in the band layout of sys%d, in RCM order: the
    !> dynamic stiffness of any harmonic is then their combination (receptance_banded).
    subroutine band_layout(sys, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: i, k, stat
        logical :: ok
        info = FRIROM_OK
        allocate (sys%dband(size(sys%d%ab, 1), size(sys%d%ab, 2), 3), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'receptance: band of K, M, C')
            return
        end if
        ok = .true.
        call put(sys%k, 1_ip)
        call put(sys%m, 2_ip)
        call put(sys%c, 3_ip)
        if (.not. ok) call set_status(info, FRIROM_ERR_MODEL, errmsg, 'receptance: entry '// &
                                      'outside band')

    contains

        subroutine put(a, m)
            type(csr_matrix), intent(in) :: a
            integer(ip), intent(in) :: m
            call zband_zero(sys%d)
            do i = 1, sys%ndof
                do k = a%p(i), a%p(i + 1) - 1
                    call zband_add(sys%d, sys%iperm(i), sys%iperm(a%i(k)), &
                                   cmplx(a%x(k), 0.0_wp, wp), ok)
                end do
            end do
            sys%dband(:, :, m) = real(sys%d%ab, wp)
        end subroutine put
    end subroutine band_layout

    !> receptance_banded's columns (into the allocated ymat) by a sparse LU of D_h per
    !> harmonic (MUMPS, one triangle of K, M, C in coordinate form, natural DoF order:
    !> MUMPS orders itself).
    subroutine receptance_sparse(sys, w, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(in) :: w
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: h, i, k, j, nz, ndof, nnl
        integer(ip), allocatable :: irn(:), jcn(:)
        complex(wp), allocatable :: a(:), rhs(:, :)
        real(wp) :: hw
        info = FRIROM_OK
        ndof = sys%ndof
        nnl = sys%nnl
        nz = size(sys%k%i) + size(sys%m%i) + size(sys%c%i)
        allocate (irn(nz), jcn(nz), a(nz), rhs(ndof, nnl + 2))
        do h = 0, sys%nh
            hw = h*w
            nz = 0
            do i = 1, ndof
                call add(sys%k, i, (1.0_wp, 0.0_wp))
                call add(sys%m, i, cmplx(-hw*hw, 0.0_wp, wp))
                if (h > 0) call add(sys%c, i, cmplx(0.0_wp, hw, wp))
            end do
            rhs = (0.0_wp, 0.0_wp)
            do j = 1, nnl
                do k = sys%t%p(j), sys%t%p(j + 1) - 1
                    rhs(sys%t%i(k), j) = rhs(sys%t%i(k), j) + sys%t%x(k)
                end do
            end do
            rhs(:, nnl + 1) = harm_col(sys%fe0, h)
            rhs(:, nnl + 2) = harm_col(sys%fe1, h)
            call zsparse_solve(ndof, irn(:nz), jcn(:nz), a(:nz), rhs, info, errmsg)
            if (info /= 0) return
            sys%ymat(:, :, h) = rhs(:, 1:nnl)
            sys%ye0(:, h) = rhs(:, nnl + 1)
            sys%ye1(:, h) = rhs(:, nnl + 2)
        end do

    contains

        !> Entries of row i on or right of the diagonal of a, times f.
        subroutine add(mat, i, f)
            type(csr_matrix), intent(in) :: mat
            integer(ip), intent(in) :: i
            complex(wp), intent(in) :: f
            integer(ip) :: kk
            do kk = mat%p(i), mat%p(i + 1) - 1
                if (mat%i(kk) < i) cycle
                nz = nz + 1
                irn(nz) = i
                jcn(nz) = mat%i(kk)
                a(nz) = f*mat%x(kk)
            end do
        end subroutine add
    end subroutine receptance_sparse
end submodule frirom_hbm_receptances
