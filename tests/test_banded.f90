!> frirom_banded: banded LU solves (real and complex) against dense LAPACK solves of the same
!> matrices, and the reverse Cuthill-McKee order on a randomly numbered chain and grid.
program test_banded
    use frirom_kinds, only: wp, ip
    use frirom_check, only: check, check_done, fixed_seed
    use frirom_banded
    implicit none
    integer(ip), parameter :: n = 60, kl = 3, ku = 5
    type(band_matrix) :: a
    type(zband_matrix) :: z
    real(wp) :: dense(n, n), b(n, 2), bd(n, 2), rr(n, n), ri(n, n)
    complex(wp) :: zd(n, n), zb(n, 1), zbd(n, 1)
    integer(ip) :: info, i, j, ipiv(n), linfo
    character(len=256) :: msg
    logical :: ok
    msg = ''
    call fixed_seed(17)
    call random_number(rr)
    call random_number(ri)
    ! real: random band, diagonally weighted so that pivoting is exercised but not needed
    call band_init(a, n, kl, ku, info, msg)
    call check(info == 0, 'band_init')
    call zband_init(z, n, kl, ku, info, msg)
    dense = 0.0_wp
    zd = (0.0_wp, 0.0_wp)
    ok = .true.
    do j = 1, n
        do i = max(1, j - ku), min(n, j + kl)
            dense(i, j) = rr(i, j) - 0.5_wp
            if (i == j) dense(i, j) = dense(i, j) + 1.0_wp
            zd(i, j) = cmplx(dense(i, j), ri(i, j) - 0.5_wp, wp)
            call band_add(a, i, j, dense(i, j), ok)
            call zband_add(z, i, j, zd(i, j), ok)
        end do
    end do
    call check(ok, 'band_add inside band')
    call band_add(a, n, 1, 1.0_wp, ok)
    call check(.not. ok, 'band_add outside band is reported')
    call random_number(b)
    bd = b
    zb(:, 1) = cmplx(b(:, 1), b(:, 2), wp)
    zbd = zb
    call band_factor(a, info, msg)
    call check(info == 0, 'band_factor: '//trim(msg))
    call band_solve(a, b, info, msg)
    call dgesv(n, 2, dense, n, ipiv, bd, n, linfo)
    ! both are backward stable solves of a well conditioned system: agree to ~1e-12
    call check(maxval(abs(b - bd)) < 1.0e-10_wp*maxval(abs(bd)), 'dgbtrs vs dgesv')
    call zband_factor(z, info, msg)
    call zband_solve(z, zb, info, msg)
    call zgesv(n, 1, zd, n, ipiv, zbd, n, linfo)
    call check(maxval(abs(zb - zbd)) < 1.0e-10_wp*maxval(abs(zbd)), 'zgbtrs vs zgesv')
    print '(a,es10.2)', 'banded vs dense, real: ', maxval(abs(b - bd))
    ! a singular matrix is reported with the routine name
    call band_init(a, 4, 1, 1, info, msg)
    call band_factor(a, info, msg)
    call check(info /= 0 .and. index(msg, 'dgbtrf') > 0, 'singular reported')
    call rcm_chain()
    call rcm_grid()
    call check_done('test_banded')

contains

    !> A chain numbered at random has a large bandwidth; RCM must bring it back to 1.
    subroutine rcm_chain()
        integer(ip), parameter :: m = 200
        integer(ip) :: lab(m), p(m + 1), idx(3*m), perm(m), iperm(m), k, t, node
        real(wp) :: u
        lab = [(k, k = 1, m)]
        do k = m, 2, -1
            call random_number(u)
            t = 1 + int(u*k)
            node = lab(k)
            lab(k) = lab(t)
            lab(t) = node
        end do
        call chain_csr(m, lab, p, idx)
        iperm = [(k, k = 1, m)]
        call rcm_order(p, idx, perm, info, msg)
        call check(info == 0, 'rcm_order chain')
        do k = 1, m
            iperm(perm(k)) = k
        end do
        call check(band_width(p, idx, iperm) == 1, 'RCM bandwidth of a chain is 1')
    end subroutine rcm_chain

    subroutine chain_csr(m, lab, p, idx)
        integer(ip), intent(in) :: m, lab(:)
        integer(ip), intent(out) :: p(:), idx(:)
        integer(ip) :: nb(m, 3), cnt(m), k, i
        cnt = 0
        do k = 1, m
            i = lab(k)
            cnt(i) = cnt(i) + 1
            nb(i, cnt(i)) = i
            if (k > 1) then
                cnt(i) = cnt(i) + 1
                nb(i, cnt(i)) = lab(k - 1)
            end if
            if (k < m) then
                cnt(i) = cnt(i) + 1
                nb(i, cnt(i)) = lab(k + 1)
            end if
        end do
        p(1) = 1
        do i = 1, m
            idx(p(i):p(i) + cnt(i) - 1) = nb(i, 1:cnt(i))
            p(i + 1) = p(i) + cnt(i)
        end do
    end subroutine chain_csr

    !> A 10 x 30 grid numbered along the long side first (bandwidth 30): RCM must find the
    !> short-side numbering's bandwidth, at most 11.
    subroutine rcm_grid()
        integer(ip), parameter :: nx = 30, ny = 10, m = nx*ny
        integer(ip) :: p(m + 1), idx(5*m), perm(m), iperm(m), i, j, k, c, bw0
        c = 0
        p(1) = 1
        do j = 1, ny
            do i = 1, nx
                k = i + nx*(j - 1)
                if (j > 1) call put(idx, c, k - nx)
                if (i > 1) call put(idx, c, k - 1)
                call put(idx, c, k)
                if (i < nx) call put(idx, c, k + 1)
                if (j < ny) call put(idx, c, k + nx)
                p(k + 1) = c + 1
            end do
        end do
        iperm = [(k, k = 1, m)]
        bw0 = band_width(p, idx(:c), iperm)
        call rcm_order(p, idx(:c), perm, info, msg)
        do k = 1, m
            iperm(perm(k)) = k
        end do
        print '(a,i0,a,i0)', 'grid bandwidth natural ', bw0, ', RCM ', &
            band_width(p, idx(:c), iperm)
        call check(band_width(p, idx(:c), iperm) <= ny + 1, 'RCM bandwidth of a grid')
    end subroutine rcm_grid

    subroutine put(idx, c, v)
        integer(ip), intent(inout) :: idx(:), c
        integer(ip), intent(in) :: v
        c = c + 1
        idx(c) = v
    end subroutine put
end program test_banded
