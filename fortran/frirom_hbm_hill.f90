!> Hill stability of frirom_hbm's periodic solutions: Floquet exponents from the
!> linearised harmonic balance equations over all DoFs x harmonics.
submodule (frirom_hbm) frirom_hbm_hill
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_ALLOC, FRIROM_ERR_LAPACK, &
                             FRIROM_ERR_SINGULAR, set_status
    implicit none

contains

    module procedure hbm_hill
        integer(ip), parameter :: NMAX = 4000
        real(wp), allocatable :: jm(:, :), d1(:, :), md(:, :), a(:, :), wr(:), wi(:), &
                                 work(:), key(:)
        real(wp), allocatable :: vr(:, :)
        real(wp) :: w, s, hw, vl(1, 1), wq(1)
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
        ! contact Jacobians at the solution (a condensed system's G has the nl DoFs as columns)
        call hbm_contact_forces(sys, y, .true., info, errmsg)
        if (info /= 0) return
        select type (sys)
        type is (hbm_condensed)
            colmap = sys%nl
        class default
            colmap = [(i, i = 1, nd)]
        end select
        jm = 0.0_wp
        d1 = 0.0_wp
        md = 0.0_wp
        call contact_assemble(sys%cs, kd=jm, info=info, errmsg=errmsg, colmap=colmap, ldc=nd)
        if (info /= 0) return
        do i = 1, nd
            do k = sys%m%p(i), sys%m%p(i + 1) - 1
                md(i, sys%m%i(k)) = md(i, sys%m%i(k)) + sys%m%x(k)
            end do
            do c = 1, nc
                call add_row(jm, sys%k, nd, i, c, c, 1.0_wp)
                call add_row(d1, sys%c, nd, i, c, c, 1.0_wp)
            end do
            do h = 1, sys%nh
                hw = h*w
                call add_row(jm, sys%m, nd, i, 2*h, 2*h, -hw*hw)
                call add_row(jm, sys%m, nd, i, 2*h + 1, 2*h + 1, -hw*hw)
                call add_row(jm, sys%c, nd, i, 2*h, 2*h + 1, hw)
                call add_row(jm, sys%c, nd, i, 2*h + 1, 2*h, -hw)
                call add_row(d1, sys%m, nd, i, 2*h, 2*h + 1, 2*hw)
                call add_row(d1, sys%m, nd, i, 2*h + 1, 2*h, -2*hw)
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
        allocate (vr(2*n, 2*n), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'Hill eigenvectors')
            return
        end if
        call dgeev('N', 'V', 2*n, a, 2*n, wr, wi, vl, 1, vr, 2*n, wq, -1, linfo)
        lwork = int(wq(1))
        allocate (work(lwork))
        call dgeev('N', 'V', 2*n, a, 2*n, wr, wi, vl, 1, vr, 2*n, work, lwork, linfo)
        if (linfo /= 0) then
            call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'Hill: dgeev did not converge')
            return
        end if
        ! each exponent repeats 2H+1 times shifted by i h w, its eigenvector shifted by h
        ! harmonics: keep the 2 ndof whose eigenvectors are centred on harmonic 0
        call harmonic_centroids(vr, wi, nd, sys%nh, key)
        key = abs(key)
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
    end procedure hbm_hill

    !> Harmonic centroid of each eigenvector of the Hill matrix: sum_k k |p_k|^2 / sum_k
    !> |p_k|^2 over the complex harmonics k = -H..H of its displacement part p (rows
    !> 1..nd(2H+1) of vr, slot 1 constant, 2h cos, 2h+1 sin). dgeev's storage: a complex
    !> pair j, j+1 (wi(j) > 0) has eigenvectors vr(:, j) +- i vr(:, j+1); a real
    !> eigenvector has centroid 0.
    pure subroutine harmonic_centroids(vr, wi, nd, nh, cen)
        real(wp), intent(in) :: vr(:, :)  !! (2n, 2n) right eigenvectors from dgeev
        real(wp), intent(in) :: wi(:)     !! (2n) imaginary parts of the eigenvalues
        integer(ip), intent(in) :: nd, nh
        real(wp), intent(out) :: cen(:)   !! (2n) centroids, harmonic index
        integer(ip) :: j, h, ic, is
        real(wp) :: tot, mom
        cen = 0.0_wp
        j = 1
        do while (j <= size(wi))
            if (wi(j) == 0.0_wp) then
                j = j + 1
                cycle
            end if
            ! |p_h|^2 - |p_-h|^2 = xr_c . xi_s - xi_c . xr_s for p = xr + i xi
            tot = sum(vr(1:nd, j)**2) + sum(vr(1:nd, j + 1)**2)
            mom = 0.0_wp
            do h = 1, nh
                ic = nd*(2*h - 1)
                is = nd*(2*h)
                tot = tot + 0.5_wp*(sum(vr(ic + 1:ic + nd, j:j + 1)**2) + &
                                    sum(vr(is + 1:is + nd, j:j + 1)**2))
                mom = mom + h*(dot_product(vr(ic + 1:ic + nd, j), vr(is + 1:is + nd, j + 1)) &
                               - dot_product(vr(ic + 1:ic + nd, j + 1), vr(is + 1:is + nd, j)))
            end do
            cen(j) = mom/max(tot, tiny(1.0_wp))
            cen(j + 1) = -cen(j)
            j = j + 2
        end do
    end subroutine harmonic_centroids

    !> a(slot r of DoF i, slot c of DoF j) += alpha s(i, j) over the entries of row i of s,
    !> for a dense a whose slot c of DoF j is index j + nd (c - 1).
    pure subroutine add_row(a, s, nd, i, r, c, alpha)
        real(wp), intent(inout) :: a(:, :)
        type(csr_matrix), intent(in) :: s
        integer(ip), intent(in) :: nd, i, r, c
        real(wp), intent(in) :: alpha
        integer(ip) :: k, ia, ja
        ia = i + nd*(r - 1)
        do k = s%p(i), s%p(i + 1) - 1
            ja = s%i(k) + nd*(c - 1)
            a(ia, ja) = a(ia, ja) + alpha*s%x(k)
        end do
    end subroutine add_row
end submodule frirom_hbm_hill
