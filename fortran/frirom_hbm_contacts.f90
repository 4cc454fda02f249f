!> CSR helpers and the contact set of frirom_hbm: G x, the AFT of every contact group,
!> G^T f and G^T J G, and the sliders a converged point hands on.
submodule (frirom_hbm) frirom_hbm_contacts
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_PARAM, FRIROM_ERR_MODEL, &
                             set_status
    use frirom_banded, only: band_add
    use frirom_aft, only: aft_eval, law_nslider
    implicit none

contains

    module procedure csr_matvec_add_real
        integer(ip) :: i, k
        real(wp) :: s
        do i = 1, a%nrow
            s = 0.0_wp
            do k = a%p(i), a%p(i + 1) - 1
                s = s + a%x(k)*x(a%i(k))
            end do
            y(i) = y(i) + alpha*s
        end do
    end procedure csr_matvec_add_real

    module procedure csr_matvec_add_cplx
        real(wp), allocatable :: sr(:), si(:)
        allocate (sr(a%nrow), si(a%nrow))
        sr = 0.0_wp
        si = 0.0_wp
        call csr_matvec_add_real(a, x%re, sr, 1.0_wp)
        call csr_matvec_add_real(a, x%im, si, 1.0_wp)
        y(:a%nrow) = y(:a%nrow) + alpha*cmplx(sr, si, wp)
    end procedure csr_matvec_add_cplx

    module procedure csr_set
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
    end procedure csr_set

    module procedure contact_eval
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
    end procedure contact_eval

    module procedure contact_assemble
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
    end procedure contact_assemble

    module procedure hbm_contact_forces
        integer(ip) :: i, nc
        real(wp) :: t0
        logical :: count
        count = .false.
        if (present(timed)) count = timed
        nc = sys%nc
        select type (sys)
        type is (hbm_condensed)
            sys%xd = reshape(y, [sys%nnl, nc])
        class default
            do i = 1, sys%ndof
                sys%xd(i, :) = y(nc*(sys%iperm(i) - 1) + 1:nc*sys%iperm(i))
            end do
        end select
        t0 = wtime()
        call contact_eval(sys%cs, sys%plan, sys%xd, sys%fd, jac, info, errmsg, carry)
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

    module procedure hbm_sliders
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
    end procedure hbm_sliders

end submodule frirom_hbm_contacts
