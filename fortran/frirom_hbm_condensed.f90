!> The condensed formulation of frirom_hbm (Eq. 5-9 of the reference) in the coordinates
!> u = T x (T = P: the nonlinear DoFs; T = G: the contacts' local relative displacements):
!> receptances R_h = T D_h^-1 T^T from a banded factorisation per harmonic, or from modes
!> (all modes of a reduced model: exact; fewer: truncated), the residual
!> R = U - T X_e + R_h F_c(U) with J = I + R_h dF_c/dU assembled element by element
!> (dF_c/dU is block diagonal per contact element), and the outputs by Eq. 9.
submodule (frirom_hbm) frirom_hbm_condensed
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_PARAM, FRIROM_ERR_ALLOC, &
                             FRIROM_ERR_LAPACK, FRIROM_ERR_SINGULAR, FRIROM_ERR_MODEL, &
                             FRIROM_ERR_NONFINITE, set_status
    use frirom_banded, only: zband_init, zband_zero, zband_add, zband_factor, zband_solve
    use frirom_zsparse, only: zsparse_solve
    implicit none

    !> GMRES (Krylov mode): relative residual, iteration limit before the J is factorised,
    !> iterations above which the next J is factorised.
    real(wp), parameter :: GM_TOL = 1.0e-11_wp
    integer(ip), parameter :: GM_MAXIT = 40, GM_REFRESH = 8

contains

    module procedure cond_init
        integer(ip) :: nu, n, stat, g, e, r, k, ne_tot, ie, nk
        integer(ip), allocatable :: cols(:)
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
        allocate (sys%ecp(ne_tot + 1), cols(size(sys%cs%g%i)))
        sys%ecp(1) = 1
        ie = 0
        nk = 0
        do g = 1, size(sys%cs%grp)
            associate (gr => sys%cs%grp(g), gg => sys%cs%g)
                do e = 1, gr%ne
                    ie = ie + 1
                    do r = gr%row0 + (e - 1)*gr%ndir + 1, gr%row0 + e*gr%ndir
                        do k = gg%p(r), gg%p(r + 1) - 1
                            if (any(cols(sys%ecp(ie):nk) == gg%i(k))) cycle
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

    !> Whether solves go through GMRES on jcur (see hbm_condensed%krylov).
    pure logical function use_krylov(sys)
        type(hbm_condensed), intent(in) :: sys
        use_krylov = sys%krylov == 1
    end function use_krylov

    module procedure hbm_set_modes
        integer(ip) :: nm
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
        integer(ip) :: h, r, nr, nu, stat
        real(wp), allocatable :: fr(:, :), q(:, :)
        info = FRIROM_OK
        select type (sys => sysc)
        type is (hbm_condensed)
            nu = sys%nnl
            nr = nu + size(sys%outdofs)
            if (allocated(sys%phr)) deallocate (sys%phr)
            if (allocated(sys%psi)) deallocate (sys%psi)
            if (allocated(sys%wm)) deallocate (sys%wm, sys%zm, sys%g, sys%dg, sys%qf, sys%qf1)
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
            if (stat /= 0) then
                call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'modes: rows of the modes')
                return
            end if
            sys%wm = wm
            sys%zm = zm
            if (present(phi)) then
                ! rows T phi and phi(outdofs); q = phi^T [fe0_h, fe1_h] (Re, Im) in one product
                call csr_rows(sys%t, phi, sys%phr(1:nu, :))
                sys%phr(nu + 1:, :) = phi(sys%outdofs, :)
                do h = 0, sys%nh
                    fr(:, 4*h + 1) = real(harm_col(sys%fe0, h), wp)
                    fr(:, 4*h + 2) = aimag(harm_col(sys%fe0, h))
                    fr(:, 4*h + 3) = real(harm_col(sys%fe1, h), wp)
                    fr(:, 4*h + 4) = aimag(harm_col(sys%fe1, h))
                end do
                call dgemm('T', 'N', nm, 4*(sys%nh + 1), sys%ndof, 1.0_wp, phi, sys%ndof, fr, &
                           sys%ndof, 0.0_wp, q, nm)
                do h = 0, sys%nh
                    sys%qf(:, h) = cmplx(q(:, 4*h + 1), q(:, 4*h + 2), wp)
                    sys%qf1(:, h) = cmplx(q(:, 4*h + 3), q(:, 4*h + 4), wp)
                end do
            else
                do h = 0, sys%nh
                    do r = 1, nm
                        sys%psi(1:nu, r, h) = csr_rows_z(sys%t, psi(:, r, h))
                        sys%psi(nu + 1:, r, h) = psi(sys%outdofs, r, h)
                        sys%qf(r, h) = sum(conjg(psi(:, r, h))*harm_col(sys%fe0, h))
                        sys%qf1(r, h) = sum(conjg(psi(:, r, h))*harm_col(sys%fe1, h))
                    end do
                end do
            end if
            if (any(sys%wm <= 0.0_wp) .or. any(sys%zm < 0.0_wp) .or. &
                .not. all(abs(sys%wm) + abs(sys%zm) <= huge(1.0_wp))) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'modes: need omega > 0 and '// &
                                'zeta >= 0, finite')
                return
            end if
            sys%modal = .true.
            sys%w_cache = -1.0_wp
            sys%w_rmat = -1.0_wp
        class default
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'modal superposition needs the '// &
                            'condensed formulation')
        end select
    end subroutine modal_store

    !> b = A x for a real CSR A and the columns of a dense x (rows of x = columns of A).
    subroutine csr_rows(a, x, b)
        type(csr_matrix), intent(in) :: a
        real(wp), intent(in) :: x(:, :)
        real(wp), intent(out) :: b(:, :)
        integer(ip) :: i, k
        do i = 1, a%nrow
            b(i, :) = 0.0_wp
            do k = a%p(i), a%p(i + 1) - 1
                b(i, :) = b(i, :) + a%x(k)*x(a%i(k), :)
            end do
        end do
    end subroutine csr_rows

    !> A z for a real CSR A and a complex vector z.
    pure function csr_rows_z(a, z) result(b)
        type(csr_matrix), intent(in) :: a
        complex(wp), intent(in) :: z(:)
        complex(wp) :: b(a%nrow)
        integer(ip) :: i, k
        do i = 1, a%nrow
            b(i) = (0.0_wp, 0.0_wp)
            do k = a%p(i), a%p(i + 1) - 1
                b(i) = b(i) + a%x(k)*z(a%i(k))
            end do
        end do
    end function csr_rows_z

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

    !> Set harmonic h of every row of a real-harmonic array a(:, 2H+1) from its complex
    !> amplitudes z (the inverse of harm_col).
    pure subroutine harm_set(a, h, z)
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
    subroutine modal_apply(sys, h, lo, hi, x, b)
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
    subroutine modal_project(sys, h, f, v)
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
    subroutine modal_rmat(sys)
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
    subroutine cond_receptance(sys, w, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(in) :: w
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: h, j, k
        real(wp) :: t0
        complex(wp), allocatable :: row(:)
        info = FRIROM_OK
        t0 = wtime()
        if (sys%modal) then
            call modal_factors(sys, w)
        else
            call receptance_banded(sys, w, info, errmsg)
            if (info /= 0) return
            allocate (row(sys%nnl))
            do h = 0, sys%nh
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
    !> D_h = K + i h w C - (h w)^2 M per harmonic.
    subroutine receptance_banded(sys, w, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(in) :: w
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: h, i, k, j, ndof, nnl, stat
        complex(wp), allocatable :: rhs(:, :)
        real(wp) :: hw
        logical :: ok
        info = FRIROM_OK
        ndof = sys%ndof
        nnl = sys%nnl
        if (sys%sparse_lu) then
            call receptance_sparse(sys, w, info, errmsg)
            return
        end if
        if (.not. allocated(sys%d%ab)) then
            call zband_init(sys%d, sys%ndof, sys%bw, sys%bw, info, errmsg)
            if (info /= 0) return
        end if
        if (.not. allocated(sys%ymat)) then
            allocate (sys%ymat(ndof, nnl, 0:sys%nh), stat=stat)
            if (stat /= 0) then
                call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'condensed: receptance columns')
                return
            end if
        end if
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

    !> receptance_banded's columns by a sparse LU of D_h per harmonic (MUMPS, one triangle
    !> of K, M, C in coordinate form; natural DoF order: MUMPS orders itself).
    subroutine receptance_sparse(sys, w, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(in) :: w
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: h, i, k, j, nz, ndof, nnl, stat
        integer(ip), allocatable :: irn(:), jcn(:)
        complex(wp), allocatable :: a(:), rhs(:, :)
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

    module procedure cond_eval
        real(wp) :: w, s, nx, nxe, nhf
        integer(ip) :: nnl, nc, h, n, nm
        complex(wp), allocatable :: fc(:), z(:), dz(:), rh(:), xe(:), v(:), x3(:, :), b3(:, :)
        real(wp), allocatable :: r2(:, :), rl2(:, :)   !! (nnl, nc) r and rlam by harmonic
        info = FRIROM_OK
        nnl = this%nnl
        nc = this%nc
        n = this%n
        call freq_load(this, lam, w, s)
        if (w /= this%w_cache) then
            call cond_receptance(this, w, info, errmsg)
            if (info /= 0) return
        end if
        call hbm_contact_forces(this, y, jac, info, errmsg, timed=.true.)
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
        nx = norm2(y)
        do h = 0, this%nh
            fc = harm_col(this%fd, h)
            if (this%modal) then
                ! T x = A g (q - A^H fc): forced part, contact part, d/dw (one product)
                call modal_project(this, h, fc, v)
                associate (g => this%g(:, h), q => this%qf(:, h) + s*this%qf1(:, h))
                    x3(:, 1) = g*q
                    x3(:, 2) = g*v
                    if (this%mode /= HBM_FREQUENCY) then
                        x3(:, 3) = -g*this%qf1(:, h)
                    else
                        x3(:, 3) = -this%dg(:, h)*(q - v)
                    end if
                end associate
                call modal_apply(this, h, 1, nnl, x3, b3)
                xe = b3(:, 1)
                rh = b3(:, 2)
            else
                xe = this%tye0(:, h) + s*this%tye1(:, h)
                rh = cmplx(matmul(this%ar(:, :, h), real(fc, wp)) - &
                           matmul(this%ai(:, :, h), aimag(fc)), &
                           matmul(this%ar(:, :, h), aimag(fc)) + &
                           matmul(this%ai(:, :, h), real(fc, wp)), wp)
            end if
            nhf = nhf + sum(abs(rh)**2)
            nxe = nxe + sum(abs(xe)**2)
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
        r = reshape(r2, [n])
        rlam = reshape(rl2, [n])
        rref = max(sqrt(nxe), nx, sqrt(nhf))
        if (.not. jac) return
        if (this%modal) then
            this%gj = this%g
            this%wj = w
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
        integer(ip) :: d1, d2, s1, c1, k, r, pos, stat
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
        if (krylov .and. .not. allocated(sys%jcur)) then
            allocate (sys%jcur(n, n), stat=stat)
            if (stat /= 0) then
                call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'condensed: Krylov Jacobian')
                return
            end if
        end if
        if (krylov) then
            call move_alloc(sys%jcur, jt)
        else
            call move_alloc(sys%jm, jt)
        end if
        jt = 0.0_wp
        ie = 0
        ! elements that each read most coordinates (an interface reduced to a few
        ! generalised DoFs): sum their blocks into dF_c/dU first, then dense products
        dense = sum(real(sys%ecp(2:) - sys%ecp(:size(sys%ecp) - 1), wp)**2)*nc**2 > &
                real(n, wp)**2
        if (dense) then
            allocate (kc(n, n), stat=stat)
            if (stat /= 0) then
                call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'condensed: contact Jacobian')
                return
            end if
            kc = 0.0_wp
        end if
        do g = 1, size(sys%cs%grp)
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
                        if (dense) then
                            do s2 = 1, m
                                do c2 = 1, nc
                                    col = sc(s2) + nu*(c2 - 1)
                                    q = c2 + nc*(s2 - 1)
                                    do s1 = 1, m
                                        do c1 = 1, nc
                                            i = sc(s1) + nu*(c1 - 1)
                                            kc(i, col) = kc(i, col) + ke(c1 + nc*(s1 - 1), q)
                                        end do
                                    end do
                                end do
                            end do
                            deallocate (ge, kt, ke)
                            cycle
                        end if
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
        if (dense) call jac_dense(sys, n, kc, jt)
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
            if (h == 0) then
                call dgemm('N', 'N', nnl, n, nnl, 1.0_wp, sys%ar(:, :, 0), nnl, kc, n, &
                           0.0_wp, jm, n)
            else
                ca = nnl*(2*h - 1) + 1
                cb = nnl*(2*h) + 1
                ! a-rows: A Kc_a + B Kc_b ; b-rows: -B Kc_a + A Kc_b
                call dgemm('N', 'N', nnl, n, nnl, 1.0_wp, sys%ar(:, :, h), nnl, kc(ca, 1), n, &
                           0.0_wp, jm(ca, 1), n)
                call dgemm('N', 'N', nnl, n, nnl, 1.0_wp, sys%ai(:, :, h), nnl, kc(cb, 1), n, &
                           1.0_wp, jm(ca, 1), n)
                call dgemm('N', 'N', nnl, n, nnl, -1.0_wp, sys%ai(:, :, h), nnl, kc(ca, 1), &
                           n, 0.0_wp, jm(cb, 1), n)
                call dgemm('N', 'N', nnl, n, nnl, 1.0_wp, sys%ar(:, :, h), nnl, kc(cb, 1), n, &
                           1.0_wp, jm(cb, 1), n)
            end if
        end do
    end subroutine jac_dense

    !> LU of J (jm := jcur first in Krylov mode).
    subroutine cond_factor(sys, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: n, linfo
        real(wp) :: t0
        info = FRIROM_OK
        n = sys%n
        t0 = wtime()
        if (use_krylov(sys)) sys%jm = sys%jcur
        call dgetrf(n, n, sys%jm, n, sys%ipiv, linfo)
        sys%timers(T_FACT) = sys%timers(T_FACT) + wtime() - t0
        sys%timers(N_FACT) = sys%timers(N_FACT) + 1
        sys%lu_fresh = linfo == 0
        sys%lu_any = linfo == 0
        sys%refresh = .false.
        if (linfo > 0) then
            call set_status(info, FRIROM_ERR_SINGULAR, errmsg, 'condensed Jacobian: dgetrf '// &
                            'zero pivot')
        else if (linfo < 0) then
            call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'dgetrf: illegal argument')
        end if
    end subroutine cond_factor

    module procedure cond_solve
        integer(ip) :: linfo, j, its
        real(wp) :: t0
        logical :: ok
        info = FRIROM_OK
        t0 = wtime()
        if (use_krylov(this) .and. .not. this%lu_fresh) then
            do j = 1, size(b, 2)
                call gmres(this, b(:, j), its, ok)
                this%timers(N_KRYLOV) = this%timers(N_KRYLOV) + its
                ! a preconditioner that needs many iterations is renewed at the next J
                if (its > GM_REFRESH) this%refresh = .true.
                if (ok) cycle
                ! too slow: factorise this J and solve the remaining columns directly
                this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
                if (this%jfree) then
                    call modal_rmat(this)
                    this%jfree = .false.
                    this%refresh = .true.
                    call cond_jacobian(this, info, errmsg)
                else
                    call cond_factor(this, info, errmsg)
                end if
                if (info /= 0) return
                t0 = wtime()
                exit
            end do
            if (.not. this%lu_fresh) then
                this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
                return
            end if
            call dgetrs('N', this%n, size(b, 2) - j + 1, this%jm, this%n, this%ipiv, b(:, j:), &
                        size(b, 1), linfo)
        else
            call dgetrs('N', this%n, size(b, 2), this%jm, this%n, this%ipiv, b, size(b, 1), &
                        linfo)
        end if
        this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
        if (linfo /= 0) call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'dgetrs failed')
    end procedure cond_solve

    !> y = J x: the assembled jcur, or matrix-free (jfree: modal route) as
    !> x + R_h G^T J_loc G x at the Jacobian's frequency, element by element and mode by
    !> mode (R_h = A diag(g) A^H never formed).
    subroutine jmul(sys, x, y)
        type(hbm_condensed), intent(in) :: sys
        real(wp), intent(in) :: x(:)
        real(wp), intent(out) :: y(:)
        real(wp), allocatable :: xv(:, :), f(:, :), xl(:, :), fl(:), y2(:, :)
        complex(wp), allocatable :: fc(:), v(:, :), b1(:, :)
        integer(ip) :: n, nu, nc, g, e, d, r, k, h
        n = sys%n
        if (.not. sys%jfree) then
            call dgemm('N', 'N', n, 1, n, 1.0_wp, sys%jcur, n, x, n, 0.0_wp, y, n)
            return
        end if
        nu = sys%nnl
        nc = sys%nc
        xv = reshape(x, [nu, nc])
        allocate (f(nu, nc), y2(nu, nc), fc(nu), v(size(sys%gj, 1), 1), b1(nu, 1))
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
                    fl = matmul(gr%jac(:, :, e), reshape(xl, [nc*gr%ndir]))
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
        do h = 0, sys%nh
            fc = harm_col(f, h)
            call modal_project(sys, h, fc, v(:, 1))
            v(:, 1) = sys%gj(:, h)*v(:, 1)
            call modal_apply(sys, h, 1, nu, v, b1)
            call harm_set(y2, h, b1(:, 1))
        end do
        y = x + reshape(y2, [n])
    end subroutine jmul

    !> b := J^-1 b by restarted GMRES on jcur, right-preconditioned by the LU in jm (from
    !> an earlier J), from the preconditioned start x0 = LU^-1 b, to a residual of GM_TOL
    !> |b|; ok false (b unchanged) when GM_MAXIT iterations do not get there.
    subroutine gmres(sys, b, its, ok)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(inout) :: b(:)
        integer(ip), intent(out) :: its
        logical, intent(out) :: ok
        integer(ip), parameter :: m = 30
        real(wp), allocatable :: v(:, :), hh(:, :), cs(:), sn(:), gv(:), x(:), r(:), w(:, :)
        real(wp) :: beta, bn, tmp
        integer(ip) :: n, j, i, k, linfo
        n = sys%n
        allocate (v(n, m + 1), hh(m + 1, m), cs(m), sn(m), gv(m + 1), x(n), r(n), w(n, 1))
        its = 0
        ok = .false.
        bn = norm2(b)
        if (bn == 0.0_wp) then
            ok = .true.
            return
        end if
        w(:, 1) = b
        call dgetrs('N', n, 1, sys%jm, n, sys%ipiv, w, n, linfo)
        x = w(:, 1)
        do
            ! r = b - J x
            call jmul(sys, x, r)
            r = b - r
            beta = norm2(r)
            if (beta <= GM_TOL*bn) exit
            if (its >= GM_MAXIT) return
            v(:, 1) = r/beta
            gv = 0.0_wp
            gv(1) = beta
            k = 0
            do j = 1, m
                its = its + 1
                k = j
                ! w = J LU^-1 v_j, orthogonalised (modified Gram-Schmidt)
                w(:, 1) = v(:, j)
                call dgetrs('N', n, 1, sys%jm, n, sys%ipiv, w, n, linfo)
                call jmul(sys, w(:, 1), v(:, j + 1))
                do i = 1, j
                    hh(i, j) = dot_product(v(:, i), v(:, j + 1))
                    v(:, j + 1) = v(:, j + 1) - hh(i, j)*v(:, i)
                end do
                hh(j + 1, j) = norm2(v(:, j + 1))
                if (hh(j + 1, j) > 0.0_wp) v(:, j + 1) = v(:, j + 1)/hh(j + 1, j)
                do i = 1, j - 1
                    tmp = cs(i)*hh(i, j) + sn(i)*hh(i + 1, j)
                    hh(i + 1, j) = -sn(i)*hh(i, j) + cs(i)*hh(i + 1, j)
                    hh(i, j) = tmp
                end do
                tmp = hypot(hh(j, j), hh(j + 1, j))
                if (tmp == 0.0_wp) exit
                cs(j) = hh(j, j)/tmp
                sn(j) = hh(j + 1, j)/tmp
                hh(j, j) = tmp
                hh(j + 1, j) = 0.0_wp
                gv(j + 1) = -sn(j)*gv(j)
                gv(j) = cs(j)*gv(j)
                if (abs(gv(j + 1)) <= 0.1_wp*GM_TOL*bn .or. its >= GM_MAXIT) exit
            end do
            ! x += LU^-1 V y, H y = g (upper triangular)
            do i = k, 1, -1
                gv(i) = (gv(i) - dot_product(hh(i, i + 1:k), gv(i + 1:k)))/hh(i, i)
            end do
            call dgemm('N', 'N', n, 1, k, 1.0_wp, v, n, gv, k, 0.0_wp, w, n)
            call dgetrs('N', n, 1, sys%jm, n, sys%ipiv, w, n, linfo)
            x = x + w(:, 1)
        end do
        b = x
        ok = .true.
    end subroutine gmres

    module procedure cond_outputs
        real(wp) :: w, s
        integer(ip) :: h, j, o, nu, nout
        complex(wp), allocatable :: fc(:), z(:), v(:), x1(:, :), b1(:, :)
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
        allocate (fc(nu), z(nout))
        if (this%modal) allocate (v(size(this%g, 1)), x1(size(this%g, 1), 1), b1(nout, 1))
        do h = 0, this%nh
            fc = harm_col(this%fd, h)
            if (this%modal) then
                ! x_o = Phi_o g (q - A^H fc)
                call modal_project(this, h, fc, v)
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
