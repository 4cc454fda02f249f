!> Bodies held only by their contacts (an under-platform damper, a loose shroud): their
!> linear stiffness K is singular, so D_0 = K (the static harmonic) cannot be factorised,
!> and once such a body slips on all its contacts its mean position is not determined.
!>
!> hbm_free_bodies moves the contacts' stuck stiffness Ks (law_stuck_stiffness: kt along
!> the tangents, kn along the normal) from the contact forces into the linear part,
!> K' = K + G^T Ks G, and free_subtract takes it back off the contact forces and their
!> Jacobian, f' = f(G x) - Ks G x at every harmonic: K' x + G^T f' = K x + G^T f exactly,
!> so the solution is unchanged while every D_h' = K' + i h w C - (h w)^2 M is regular (K'
!> is the stuck structure's stiffness).
!>
!> free_subtract also holds each contact's mean relative displacement (harmonic 0) by a
!> spring FREE_PIN Ks anchored at the assembled position (zero), normals included: a
!> damper that lifts off much of the cycle at a light load leaves its normal mean nearly
!> free too (the UPD case's curves at 2-20 N turned back at their start without it); a
!> cubic spring needs no pin.
!> Where a body slips on every contact (gross slip), the equations leave its mean free: a family of solutions at
!> one frequency, J singular along it, and a continuation that drifts along the family
!> instead of moving in frequency (the stall of issue 29). The pin picks the member whose
!> contacts' means are nearest the assembled position; its force there is zero, so the
!> member solves the true equations. Where a contact sticks or slips partly, the pin adds
!> FREE_PIN Ks to its mean stiffness and moves its mean, which the preload balance keeps
!> small: the UPD case's peak moves by 0.1-0.3 % for FREE_PIN from 1e-3 to 1e-1. Weaker
!> pins (1e-6), a hold in the Jacobian alone and an anchor at the previous point's mean
!> (not a solution of the next point's equations) all failed on that case. Stateless:
!> a run restored from a checkpoint sees the same equations.
submodule (frirom_hbm) frirom_hbm_free
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_ALLOC, FRIROM_ERR_SIZE, set_status
    use frirom_aft, only: law_stuck_stiffness, LAW_CUBIC
    use frirom_csr, only: coo_csr
    implicit none

contains

    module procedure hbm_free_bodies
        integer(ip) :: g, e, r, nrows, ndof, i, k, kk, nnz, cnt, stat
        integer(ip), allocatable :: tp(:), ti(:), grow(:), mark(:), list(:), np(:), ni(:)
        real(wp), allocatable :: ks(:), tx(:), acc(:), nx(:)
        info = FRIROM_OK
        ndof = sys%ndof
        nrows = size(gp) - 1
        if (nrows < 1 .or. gp(nrows + 1) - 1 > min(size(gi), size(gx))) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'hbm_free_bodies: G pointers')
            return
        end if
        ! Ks row by row of G, kept per group for free_subtract
        allocate (ks(nrows))
        do g = 1, size(sys%cs%grp)
            associate (gr => sys%cs%grp(g))
                allocate (gr%ks(gr%ndir, gr%ne), gr%kp(gr%ndir, gr%ne))
                do e = 1, gr%ne
                    call law_stuck_stiffness(gr%law, gr%params(:, e), gr%ks(:, e))
                    gr%kp(:, e) = FREE_PIN*gr%ks(:, e)
                    if (gr%law == LAW_CUBIC) gr%kp(:, e) = 0.0_wp
                    r = gr%row0 + (e - 1)*gr%ndir
                    ks(r + 1:r + gr%ndir) = gr%ks(:, e)
                end do
            end associate
        end do
        ! G^T in CSR (tp, ti: its rows are the DoFs, ti the rows of G, tx the values)
        nnz = gp(nrows + 1) - 1
        allocate (grow(nnz), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'hbm_free_bodies: G^T')
            return
        end if
        do r = 1, nrows
            grow(gp(r):gp(r + 1) - 1) = r
        end do
        call coo_csr(ndof, nrows, gi(1:nnz), grow, gx(1:nnz), 'hbm_free_bodies: G^T', tp, ti, &
                     tx, info, errmsg)
        if (info /= 0) return
        ! K' row i = K row i + sum over G's rows r reading DoF i of G(r, i) ks_r G(r, :):
        ! a dense accumulator and the list of the columns it touched (Gustavson)
        allocate (mark(ndof), list(ndof), acc(ndof), np(ndof + 1), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'hbm_free_bodies: work')
            return
        end if
        mark = 0
        acc = 0.0_wp
        np(1) = 1
        do i = 1, ndof                  ! pass 1: the pattern's size, row by row
            call row(i)
            np(i + 1) = np(i) + cnt
            call clear()
        end do
        allocate (ni(np(ndof + 1) - 1), nx(np(ndof + 1) - 1), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'hbm_free_bodies: K + G^T Ks G')
            return
        end if
        do i = 1, ndof                  ! pass 2: the entries
            call row(i)
            ni(np(i):np(i + 1) - 1) = list(1:cnt)
            nx(np(i):np(i + 1) - 1) = acc(list(1:cnt))
            call clear()
        end do
        call csr_set(sys%k, ndof, ndof, np, ni, nx, 'K + G^T Ks G', info, errmsg)

    contains

        !> Row i of K + G^T Ks G into acc over the columns list(1:cnt).
        subroutine row(i)
            integer(ip), intent(in) :: i
            cnt = 0
            do k = sys%k%p(i), sys%k%p(i + 1) - 1
                call touch(sys%k%i(k), sys%k%x(k))
            end do
            do kk = tp(i), tp(i + 1) - 1
                r = ti(kk)
                do k = gp(r), gp(r + 1) - 1
                    call touch(gi(k), tx(kk)*ks(r)*gx(k))
                end do
            end do
        end subroutine row

        subroutine clear()
            integer(ip) :: jj
            do jj = 1, cnt
                mark(list(jj)) = 0
                acc(list(jj)) = 0.0_wp
            end do
        end subroutine clear

        subroutine touch(col, v)
            integer(ip), intent(in) :: col
            real(wp), intent(in) :: v
            if (mark(col) == 0) then
                mark(col) = 1
                cnt = cnt + 1
                list(cnt) = col
            end if
            acc(col) = acc(col) + v
        end subroutine touch
    end procedure hbm_free_bodies

    module procedure free_subtract
        integer(ip) :: e, d, c, nc, q
        nc = size(x, 1)
        do e = 1, size(x, 3)
            do d = 1, size(x, 2)
                f(:, d, e) = f(:, d, e) - ks(d, e)*x(:, d, e)
                f(1, d, e) = f(1, d, e) + kp(d, e)*x(1, d, e)
                if (.not. present(jac)) cycle
                do c = 1, nc
                    q = c + nc*(d - 1)
                    jac(q, q, e) = jac(q, q, e) - ks(d, e)
                end do
                q = 1 + nc*(d - 1)
                jac(q, q, e) = jac(q, q, e) + kp(d, e)
            end do
        end do
    end procedure free_subtract

end submodule frirom_hbm_free
