!> The full banded formulation of frirom_hbm: all DoFs x harmonics, R = D X + F_c(X) - F_e,
!> unknowns DoF by DoF in reverse Cuthill-McKee order so that J is banded (LAPACK dgbtrf).
submodule (frirom_hbm) frirom_hbm_full
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_MODEL, set_status
    use frirom_banded, only: band_init, band_zero, band_add, band_factor, band_solve
    implicit none

contains

    module procedure full_init
        integer(ip) :: kl
        sys%n = sys%ndof*sys%nc
        kl = min(sys%nc*(sys%bw + 1) - 1, sys%n - 1)
        allocate (sys%rd(sys%ndof, sys%nc))
        call band_init(sys%jb, sys%n, kl, kl, info, errmsg)
    end procedure full_init

    module procedure full_eval
        real(wp) :: w, s, t0, hw, nfe, ndx
        integer(ip) :: nc, i, h, ca, cb, k
        logical :: ok
        real(wp), allocatable :: dl(:, :), kfac(:), ma(:), cfac(:)
        integer(ip), allocatable :: kslot(:), mslot(:), cr(:), cc(:)
        info = FRIROM_OK
        nc = this%nc
        call freq_load(this, lam, w, s)
        call hbm_contact_forces(this, y, jac, info, errmsg, timed=.true.)
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
        ! harmonics 1..H alone (hbm_roundoff)
        this%rref_dyn = max(norm2(this%fe0(:, 2:) + s*this%fe1(:, 2:)), norm2(this%rd(:, 2:)), &
                            norm2(this%fd(:, 2:)))
        ! the rest forces, left out of fd and fe0 (contact_set), stay in the reference
        if (allocated(this%cs%c0)) rref = max(rref, norm2(this%cs%c0))
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
        ! The slots each matrix fills in a DoF pair's nc x nc block: K on the diagonal,
        ! -(h w)^2 M on the cosine and sine slots of harmonic h, h w C across them.
        allocate (kslot(nc), mslot(2*this%nh), cr(2*this%nh), cc(2*this%nh))
        allocate (kfac(nc), ma(2*this%nh), cfac(2*this%nh))
        kslot = [(k, k = 1, nc)]
        kfac = 1.0_wp
        do h = 1, this%nh
            hw = h*w
            mslot(2*h - 1:2*h) = [2*h, 2*h + 1]
            ma(2*h - 1:2*h) = -hw*hw
            cr(2*h - 1:2*h) = [2*h, 2*h + 1]
            cc(2*h - 1:2*h) = [2*h + 1, 2*h]
            cfac(2*h - 1:2*h) = [hw, -hw]
        end do
        do i = 1, this%ndof
            call add_row(this%jb, this%k, this%iperm, nc, i, kslot, kslot, kfac, ok)
            call add_row(this%jb, this%m, this%iperm, nc, i, mslot, mslot, ma, ok)
            call add_row(this%jb, this%c, this%iperm, nc, i, cr, cc, cfac, ok)
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
    end procedure full_eval

    !> jb(slot r(q) of DoF i, slot c(q) of DoF j) += alpha(q) A(i, j) for every entry of
    !> row i of A and every q; slot s of DoF j is unknown s + nc (iperm(j) - 1). The slots
    !> run innermost, so one entry's additions fall in one block of the band.
    subroutine add_row(jb, a, iperm, nc, i, r, c, alpha, ok)
        type(band_matrix), intent(inout) :: jb
        type(csr_matrix), intent(in) :: a
        integer(ip), intent(in) :: iperm(:), nc, i
        integer(ip), intent(in) :: r(:), c(:)     !! (nq) row and column slots
        real(wp), intent(in) :: alpha(:)          !! (nq) factors
        logical, intent(inout) :: ok   !! set to .false. when an entry falls outside the band
        integer(ip) :: k, q, ii, jj
        ii = nc*(iperm(i) - 1)
        do k = a%p(i), a%p(i + 1) - 1
            jj = nc*(iperm(a%i(k)) - 1)
            do q = 1, size(r)
                call band_add(jb, ii + r(q), jj + c(q), alpha(q)*a%x(k), ok)
            end do
        end do
    end subroutine add_row

    module procedure full_solve
        real(wp) :: t0
        t0 = wtime()
        call band_solve(this%jb, b, info, errmsg)
        this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
    end procedure full_solve

    module procedure full_outputs
        integer(ip) :: j, nc, p
        info = FRIROM_OK
        nc = this%nc
        do j = 1, size(this%outdofs)
            p = this%iperm(this%outdofs(j))
            xo(j, :) = y(nc*(p - 1) + 1:nc*p)
        end do
        if (.false.) xo(1, 1) = lam
        if (.false.) errmsg = ''
    end procedure full_outputs
end submodule frirom_hbm_full
