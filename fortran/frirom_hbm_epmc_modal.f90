!> The EPMC of frirom_hbm_epmc condensed to the contact DoFs by modal superposition (see
!> hbm_epmc_modal): the receptances of every harmonic from the modes, the artificial
!> damping xi a change of each mode's damping term, the amplitude and phase conditions on
!> the modal coordinates of harmonic 1. Harmonic h's complex amplitude is z = a - i b for
!> x = a cos + b sin.
submodule (frirom_epmc) frirom_hbm_epmc_modal
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_PARAM, FRIROM_ERR_SIZE, &
                             FRIROM_ERR_SINGULAR, FRIROM_ERR_LAPACK, set_status, itoa
    use frirom_csr, only: csr_matvec_add
    use frirom_hbm, only: contact_assemble, contact_eval, wtime, T_AFT, T_ASM, T_FACT, T_SOLVE, &
                          N_EVAL, N_FACT
    implicit none

    real(wp), parameter :: LN10 = log(10.0_wp)
    complex(wp), parameter :: IU = (0.0_wp, 1.0_wp)

contains

    module procedure hbm_epmc_modal_set
        real(wp), allocatable :: mv(:), mp0(:), pn(:)
        integer(ip) :: nd, nm, r, nnl, j
        info = FRIROM_OK
        select type (sys => sysc)
        type is (hbm_epmc_modal)
            nd = sys%ndof
            nm = size(phi, 2)
            nnl = size(nl)
            if (sys%nh < 1) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'nonlinear mode: harmonics '// &
                                '>= 1 expected')
                return
            end if
            if (size(phi0) /= nd .or. size(phi, 1) /= nd .or. nm < 1 .or. size(wm) /= nm &
                .or. size(zm) /= nm .or. nnl < 1) then
                call set_status(info, FRIROM_ERR_SIZE, errmsg, 'nonlinear mode (condensed):'// &
                                ' phi0 (ndof), modes (ndof, nm), omega, zeta (nm) and the '// &
                                'contact DoFs expected')
                return
            end if
            if (any(nl < 1) .or. any(nl > nd)) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'nonlinear mode: contact '// &
                                'DoF out of range')
                return
            end if
            if (.not. (all(wm > 0.0_wp) .and. all(zm >= 0.0_wp) .and. w0 > 0.0_wp .and. &
                       all(abs(phi) <= huge(1.0_wp)) .and. all(abs(phi0) <= huge(1.0_wp)) &
                       .and. all(abs(wm) + abs(zm) <= huge(1.0_wp)))) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'nonlinear mode (condensed):'// &
                                ' finite modes, omega > 0 (no rigid-body mode) and zeta >= 0')
                return
            end if
            sys%nm = nm
            sys%nnl = nnl
            sys%nl = nl
            sys%w0 = w0
            allocate (sys%colmap(nd))
            sys%colmap = 0
            do j = 1, nnl
                sys%colmap(nl(j)) = j
            end do
            call epmc_normalise(sys%m, phi0, 'phi', sys%phi0, mp0, info, errmsg)
            if (info /= 0) return
            allocate (sys%phn(nnl, nm), sys%pho(size(sys%outdofs), nm), sys%cph(nm), &
                      sys%qst(nm))
            do r = 1, nm
                call epmc_normalise(sys%m, phi(:, r), 'mode '//itoa(r), pn, mv, info, errmsg)
                if (info /= 0) return
                sys%phn(:, r) = pn(nl)
                sys%pho(:, r) = pn(sys%outdofs)
                sys%cph(r) = dot_product(pn, mp0)
                sys%qst(r) = dot_product(pn, sys%fe0(:, 1))
            end do
            if (norm2(sys%cph) > 0.0_wp) sys%cph = sys%cph/norm2(sys%cph)
            sys%wr = wm
            sys%zr = zm
            sys%wn = max(norm2(sys%phi0(nl)), tiny(1.0_wp))
            sys%nf = nnl*sys%nc
            sys%n = sys%nf + 2
            allocate (sys%jd(sys%n, sys%n), sys%ipiv(sys%n), sys%jp(sys%nf, sys%nf), &
                      sys%fl(nnl, sys%nc))
        class default
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'nonlinear mode: not a '// &
                            'condensed mode run')
        end select
    end procedure hbm_epmc_modal_set

    !> Contact forces fl (nnl, nc) and, into jp, their Jacobian over the physical U.
    subroutine forces(this, y, a, info, errmsg)
        type(hbm_epmc_modal), intent(inout) :: this
        real(wp), intent(in) :: y(:), a
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: c
        real(wp) :: t0
        this%xd = 0.0_wp
        do c = 1, this%nc
            this%xd(this%nl, c) = y(this%nnl*(c - 1) + 1:this%nnl*c)*merge(1.0_wp, a, c == 1)
        end do
        t0 = wtime()
        call contact_eval(this%cs, this%plan, this%xd, this%fd, .true., info, errmsg)
        this%timers(T_AFT) = this%timers(T_AFT) + wtime() - t0
        this%timers(N_EVAL) = this%timers(N_EVAL) + 1
        if (info /= 0) return
        this%fl = this%fd(this%nl, :)
        this%jp = 0.0_wp
        call contact_assemble(this%cs, kd=this%jp, info=info, errmsg=errmsg, &
                              colmap=this%colmap, ldc=this%nnl)
    end subroutine forces

    !> g_r(h w, xi) and its derivatives in w and xi.
    pure subroutine modal_g(wr, zr, h, w, xi, g, gw, gx)
        real(wp), intent(in) :: wr(:), zr(:), w, xi
        integer(ip), intent(in) :: h
        complex(wp), intent(out) :: g(:), gw(:), gx(:)
        complex(wp) :: den(size(wr))
        den = wr**2 - (h*w)**2 + IU*h*w*(2.0_wp*zr*wr - xi)
        g = 1.0_wp/den
        gw = -g**2*(-2.0_wp*h*h*w + IU*h*(2.0_wp*zr*wr - xi))
        gx = -g**2*(-IU*h*w)
    end subroutine modal_g

    module procedure epmd_eval
        real(wp) :: a, w, xi, t0, nref
        integer(ip) :: nnl, nm, nf, h, ca, cb, j
        complex(wp), allocatable :: g(:), gw(:), gx(:), p(:), q(:), z(:), dp(:, :), dz(:, :)
        real(wp), allocatable :: u(:, :), yd(:), jn(:), jw(:, :)
        call epmc_unpack(this, y, lam, a, w, xi, info, errmsg)
        if (info /= 0) return
        nnl = this%nnl
        nm = this%nm
        nf = this%nf
        call forces(this, y, a, info, errmsg)
        if (info /= 0) return
        t0 = wtime()
        u = reshape(y(1:nf), [nnl, this%nc])
        allocate (g(nm), gw(nm), gx(nm), p(nm), q(nm), z(nnl), dp(nm, nf), dz(nnl, nf), &
                  jn(nf), jw(this%n, this%n))
        ! J is assembled in jw (rlam needs it); jd keeps the LU Newton may still reuse
        jw = 0.0_wp
        ! harmonic 0: U_0 - Phi_nl diag(1/w_r^2) (Phi^T fe0 - Phi_nl^T F_0)
        r(1:nnl) = u(:, 1) - matmul(this%phn, (this%qst - matmul(transpose(this%phn), &
                                                                this%fl(:, 1)))/this%wr**2)
        jw(1:nnl, 1:nf) = matmul(this%phn, matmul(spread(1.0_wp/this%wr**2, 2, nnl)* &
                                      transpose(this%phn), this%jp(1:nnl, :)))
        ! the residual's reference: the size of its terms (unknowns, static load and
        ! contact force responses, each harmonic's receptance term)
        nref = max(norm2(u), norm2(matmul(this%phn, this%qst/this%wr**2)), &
                   norm2(matmul(this%phn, matmul(transpose(this%phn), this%fl(:, 1)) &
                                /this%wr**2)))
        do h = 1, this%nh
            ca = 2*h
            cb = 2*h + 1
            call modal_g(this%wr, this%zr, h, w, xi, g, gw, gx)
            p = matmul(transpose(this%phn), cmplx(this%fl(:, ca), -this%fl(:, cb), wp))
            ! U_h + Phi_nl diag(g) p / a, as (a, b) = (Re z, -Im z)
            z = matmul(this%phn, g*p)/a
            nref = max(nref, sqrt(sum(abs(z)**2)))
            r(nnl*(ca - 1) + 1:nnl*ca) = u(:, ca) + real(z)
            r(nnl*(cb - 1) + 1:nnl*cb) = u(:, cb) - aimag(z)
            dp = matmul(transpose(this%phn), cmplx(this%jp(nnl*(ca - 1) + 1:nnl*ca, :), &
                                                   -this%jp(nnl*(cb - 1) + 1:nnl*cb, :), wp))
            dz = matmul(this%phn, diag_cscale(g, dp))/a
            jw(nnl*(ca - 1) + 1:nnl*ca, 1:nf) = real(dz)
            jw(nnl*(cb - 1) + 1:nnl*cb, 1:nf) = -aimag(dz)
            z = matmul(this%phn, gw*p)/a
            jw(nnl*(ca - 1) + 1:nnl*ca, nf + 1) = this%w0*real(z)
            jw(nnl*(cb - 1) + 1:nnl*cb, nf + 1) = -this%w0*aimag(z)
            z = matmul(this%phn, gx*p)/a
            jw(nnl*(ca - 1) + 1:nnl*ca, nf + 2) = this%w0*real(z)
            jw(nnl*(cb - 1) + 1:nnl*cb, nf + 2) = -this%w0*aimag(z)
            if (h == 1) then
                ! modal coordinates of harmonic 1 (unit amplitude): q = -g p / a
                q = -g*p/a
                r(nf + 1) = this%wn*(sum(abs(q)**2) - 1.0_wp)
                r(nf + 2) = -this%wn*dot_product(this%cph, aimag(q))
                ! dq/dU = -diag(g) dp / a
                jn = 2.0_wp*real(matmul(conjg(q), diag_cscale(-g/a, dp)))
                jw(nf + 1, 1:nf) = this%wn*jn
                jw(nf + 2, 1:nf) = -this%wn*matmul(this%cph, aimag(diag_cscale(-g/a, &
                                                                                 dp)))
                jw(nf + 1, nf + 1) = this%w0*this%wn*2.0_wp*real(sum(conjg(q)*(-gw*p/a)))
                jw(nf + 1, nf + 2) = this%w0*this%wn*2.0_wp*real(sum(conjg(q)*(-gx*p/a)))
                jw(nf + 2, nf + 1) = -this%w0*this%wn*dot_product(this%cph, &
                                                                       aimag(-gw*p/a))
                jw(nf + 2, nf + 2) = -this%w0*this%wn*dot_product(this%cph, &
                                                                       aimag(-gx*p/a))
            end if
        end do
        ! the unknowns of harmonics >= 1 are U / a: their columns times a, then I
        jw(1:nf + 2, nnl + 1:nf) = jw(1:nf + 2, nnl + 1:nf)*a
        do j = 1, nf
            jw(j, j) = jw(j, j) + 1.0_wp
        end do
        rref = max(nref, this%wn)
        this%rref_dyn = -1.0_wp
        ! dR/dlam = ln 10 (J [0; U_dyn] - [0; R_dyn]); amplitude row -2 |q|^2, phase -r
        allocate (yd(this%n))
        yd = 0.0_wp
        yd(nnl + 1:nf) = y(nnl + 1:nf)
        rlam = matmul(jw, yd)
        rlam(nnl + 1:nf) = rlam(nnl + 1:nf) - r(nnl + 1:nf)
        rlam(nf + 1) = rlam(nf + 1) - 2.0_wp*(r(nf + 1) + this%wn)
        rlam(nf + 2) = rlam(nf + 2) - r(nf + 2)
        rlam = LN10*rlam
        this%timers(T_ASM) = this%timers(T_ASM) + wtime() - t0
        if (.not. jac) return
        this%jd = jw
        if (.not. this%factor) return
        call epmc_factor(this, info, errmsg)
    end procedure epmd_eval

    !> diag(d) b (rows of b scaled).
    pure function diag_cscale(d, b) result(c)
        complex(wp), intent(in) :: d(:), b(:, :)
        complex(wp) :: c(size(b, 1), size(b, 2))
        integer(ip) :: k
        do k = 1, size(b, 2)
            c(:, k) = d*b(:, k)
        end do
    end function diag_cscale


    module procedure epmd_outputs
        real(wp) :: a, w, xi
        integer(ip) :: h, nf
        complex(wp), allocatable :: g(:), gw(:), gx(:), q(:)
        info = FRIROM_OK
        nf = this%nf
        a = 10.0_wp**lam
        w = this%w0*y(nf + 1)
        xi = this%w0*y(nf + 2)
        call forces(this, y, a, info, errmsg)
        if (info /= 0) return
        allocate (g(this%nm), gw(this%nm), gx(this%nm), q(this%nm))
        xo(:, 1) = matmul(this%pho, (this%qst - matmul(transpose(this%phn), &
                                                       this%fl(:, 1)))/this%wr**2)
        do h = 1, this%nh
            call modal_g(this%wr, this%zr, h, w, xi, g, gw, gx)
            q = -g*matmul(transpose(this%phn), cmplx(this%fl(:, 2*h), -this%fl(:, 2*h + 1), &
                                                     wp))
            xo(:, 2*h) = matmul(this%pho, real(q))
            xo(:, 2*h + 1) = -matmul(this%pho, aimag(q))
        end do
    end procedure epmd_outputs

    module procedure epmd_accept
        integer(ip) :: c
        info = FRIROM_OK
        if (size(this%cs%grp) == 0 .or. .not. this%carry) return
        this%xd = 0.0_wp
        do c = 1, this%nc
            this%xd(this%nl, c) = y(this%nnl*(c - 1) + 1:this%nnl*c)* &
                                  merge(1.0_wp, 10.0_wp**lam, c == 1)
        end do
        call contact_eval(this%cs, this%plan, this%xd, this%fd, .false., info, errmsg, &
                          carry=.true.)
    end procedure epmd_accept
end submodule frirom_hbm_epmc_modal
