!> The condensed formulation of frirom_hbm (Eq. 5-9 of the reference): receptances
!> H_h = D_h^-1 from a banded factorisation per harmonic or from modes, the residual
!> R = X_n - X_e,n + H_nn F_c(X_n) with J = I + H_nn dF_c/dX_n, and the outputs by Eq. 9.
submodule (frirom_hbm) frirom_hbm_condensed
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_PARAM, FRIROM_ERR_ALLOC, &
                             FRIROM_ERR_LAPACK, FRIROM_ERR_SINGULAR, FRIROM_ERR_MODEL, &
                             FRIROM_ERR_NONFINITE, set_status
    use frirom_banded, only: zband_init, zband_zero, zband_add, zband_factor, zband_solve
    implicit none

contains

    module procedure cond_init
        integer(ip) :: nnl, n, stat
        info = FRIROM_OK
        nnl = size(nl)
        sys%nnl = nnl
        sys%nl = nl
        n = nnl*sys%nc
        sys%n = n
        allocate (sys%ymat(sys%ndof, nnl, 0:sys%nh), sys%ye0(sys%ndof, 0:sys%nh), &
                  sys%ye1(sys%ndof, 0:sys%nh), sys%ar(nnl, nnl, 0:sys%nh), &
                  sys%ai(nnl, nnl, 0:sys%nh), sys%kc(n, n), sys%jm(n, n), sys%ipiv(n), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'condensed: receptances/Jacobian')
            return
        end if
    end procedure cond_init

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

    !> Receptance columns at w from the modes (see hbm_set_modes), on the kept rows, and
    !> the derivatives dg of the modal factors.
    subroutine receptance_modal(sys, w)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(in) :: w
        integer(ip) :: h, j, nm, nr
        real(wp) :: hw
        complex(wp), allocatable :: g(:), tmp(:, :), rows(:, :)
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
        end do
    end subroutine receptance_modal

    !> Receptances at frequency w, h = 0..H: the columns D_h^-1 P^T and D_h^-1 fe (from
    !> modes or from a banded factorisation of D_h) and H_nn = A + iB, cached for w.
    subroutine cond_receptance(sys, w, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(in) :: w
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: h, j
        real(wp) :: t0
        info = FRIROM_OK
        t0 = wtime()
        if (sys%modal) then
            call receptance_modal(sys, w)
        else
            call receptance_banded(sys, w, info, errmsg)
            if (info /= 0) return
        end if
        do h = 0, sys%nh
            do j = 1, sys%nnl
                sys%ar(j, :, h) = real(sys%ymat(sys%nl(j), :, h), wp)
                sys%ai(j, :, h) = aimag(sys%ymat(sys%nl(j), :, h))
            end do
        end do
        sys%w_cache = w
        sys%timers(T_REC) = sys%timers(T_REC) + wtime() - t0
    end subroutine cond_receptance

    !> Receptance columns D_h^-1 P^T and D_h^-1 fe at frequency w from a banded LU of
    !> D_h = K + i h w C - (h w)^2 M per harmonic.
    subroutine receptance_banded(sys, w, info, errmsg)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(in) :: w
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: h, i, k, j, ndof, nnl
        complex(wp), allocatable :: rhs(:, :)
        real(wp) :: hw
        logical :: ok
        info = FRIROM_OK
        if (.not. allocated(sys%d%ab)) then
            call zband_init(sys%d, sys%ndof, sys%bw, sys%bw, info, errmsg)
            if (info /= 0) return
        end if
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
        end do
    end subroutine receptance_banded

    module procedure cond_eval
        real(wp) :: w, s, t0, nx, nxe, nhf
        integer(ip) :: nnl, nc, h, ca, cb, n, linfo
        complex(wp), allocatable :: fc(:), z(:), dz(:), rh(:), xe(:)
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
        allocate (fc(nnl), z(this%ndof), dz(this%ndof), rh(nnl), xe(nnl), r2(nnl, nc), &
                  rl2(nnl, nc))
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
            rh = rh - xe + harm_col(this%xd, h)
            call harm_set(r2, h, rh)
            ! dR/dlam (into xe)
            if (this%mode /= HBM_FREQUENCY) then
                xe = -this%ye1(this%nl, h)
            else if (h == 0) then
                xe = (0.0_wp, 0.0_wp)
            else if (this%modal) then
                ! R = X - Phi_n diag(g) (Phi^T fe - Phi_n^T fc): dR/dw = -Phi_n dg q
                associate (pn => this%psi(1:nnl, :, h))
                    xe = -matmul(pn, this%dg(:, h)*(this%qf(:, h) - &
                                                    matmul(conjg(transpose(pn)), fc)))
                end associate
            else
                ! z = D^-1 (fe - P^T fc); dR/dw = Y^T D'(w) z, D' = i h C - 2 h^2 w M
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
    end procedure cond_eval

    module procedure cond_solve
        integer(ip) :: linfo
        real(wp) :: t0
        info = FRIROM_OK
        t0 = wtime()
        call dgetrs('N', this%n, size(b, 2), this%jm, this%n, this%ipiv, b, size(b, 1), linfo)
        this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
        if (linfo /= 0) call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'dgetrs failed')
    end procedure cond_solve

    module procedure cond_outputs
        real(wp) :: w, s
        integer(ip) :: h, j, o
        complex(wp), allocatable :: fc(:), z(:)
        info = FRIROM_OK
        call freq_load(this, lam, w, s)
        if (w /= this%w_cache) then
            call cond_receptance(this, w, info, errmsg)
            if (info /= 0) return
        end if
        call hbm_contact_forces(this, y, .false., info, errmsg)
        if (info /= 0) return
        allocate (fc(this%nnl), z(size(this%outdofs)))
        do h = 0, this%nh
            fc = harm_col(this%fd, h)
            do j = 1, size(this%outdofs)
                o = this%outdofs(j)
                z(j) = this%ye0(o, h) + s*this%ye1(o, h) - sum(this%ymat(o, :, h)*fc)
            end do
            call harm_set(xo, h, z)
        end do
    end procedure cond_outputs
end submodule frirom_hbm_condensed
