!> The modal route on a selection's kept rows (real modes): the cache of the kept mode
!> rows, the projections v = A^H fc over the modes that reach them, and the products
!> A_h x on those rows only.
submodule (frirom_hbm:frirom_hbm_condensed) frirom_hbm_keptrows
    implicit none

    !> A selected residual leaves out the modes whose terms on the kept rows sum to at most
    !> this fraction of the largest term (sel_modes, proj_safe)
    real(wp), parameter :: PROJ_SKIP = 1.0e-15_wp

contains

    module procedure sel_rows
        integer(ip) :: h, r, nm, a, b
        logical :: ok
        nm = size(sys%phr, 2)
        ok = allocated(sys%prow) .and. allocated(sys%prow_kpt)
        if (ok) ok = size(sys%prow_kpt) == size(sys%kpt) .and. size(sys%prow, 2) == nm
        if (ok) ok = all(sys%prow_kpt == sys%kpt)
        if (ok) return
        sys%prow = sys%phr(sys%kpt, :)
        sys%prow_kpt = sys%kpt
        if (allocated(sys%pamx)) deallocate (sys%pamx, sys%pan)
        allocate (sys%pamx(nm, 0:sys%nh), sys%pan(nm))
        do r = 1, nm
            sys%pan(r) = sum(sys%phr(1:sys%nnl, r)**2)
            do h = 0, sys%nh
                a = sys%kptr(h + 1)
                b = sys%kptr(h + 2) - 1
                sys%pamx(r, h) = 0.0_wp
                if (b >= a) sys%pamx(r, h) = maxval(sys%prow(a:b, r)**2)
            end do
        end do
    end procedure sel_rows

    module procedure sel_project
        real(wp) :: skip(3)
        integer(ip) :: k
        call sel_rows(sys)
        call sel_modes(sys, h, sys%qf(:, h) + s*sys%qf1(:, h), fc, use, nuse, skip)
        if (sys%orbits) then
            call project_kept(sys, h, fc, v)
        else
            call project_some(sys, fc, use(1:nuse), v)
        end if
        if (proj_safe(sys, h, sys%qf(:, h) + s*sys%qf1(:, h), use(1:nuse), v, skip)) return
        nuse = size(v)
        use = [(k, k=1, nuse)]
        if (.not. sys%orbits) call project_some(sys, fc, use, v)
    end procedure sel_project

    !> The modes r a selected residual needs at harmonic h: those whose terms on the kept
    !> rows, A_h(rows, r) x3(r, k) for the three columns of cond_eval (g q, g v, dg (q - v)
    !> or -g qf1; v = A^H fc), can exceed PROJ_SKIP / nm times the largest. A term is
    !> bounded by max|A(rows, r)| |g_r| |v_r| with |v_r| <= |A(:, r)| |fc| (Cauchy-
    !> Schwarz over every row: the forces off the selection count, so a mistuned rotor,
    !> whose forces there are large, keeps the modes they drive). skip(k): the sum of
    !> the left-out terms' bounds in column k, which proj_safe compares with the largest
    !> term actually computed. Every mode when a bound is not finite. The residual is then
    !> the same norm-wise (to PROJ_SKIP of its largest term), not row by row: a row much
    !> smaller than the largest may move by more than its own rounding, below rref's. The
    !> bounds are compared squared: terms below ~1e-154 (in the model's units) count as 0.
    subroutine sel_modes(sys, h, q, fc, use, nuse, skip)
        type(hbm_condensed), intent(in) :: sys
        integer(ip), intent(in) :: h
        complex(wp), intent(in) :: q(:), fc(:)
        integer(ip), allocatable, intent(inout) :: use(:)
        integer(ip), intent(out) :: nuse
        real(wp), intent(out) :: skip(3)
        real(wp), allocatable :: w(:, :)
        real(wp) :: nf2, q2, g2, t(3)
        integer(ip) :: r, nm
        nm = size(sys%phr, 2)
        if (allocated(use)) then
            if (size(use) /= nm) deallocate (use)
        end if
        if (.not. allocated(use)) allocate (use(nm))
        allocate (w(nm, 3))
        nf2 = sum(real(fc, wp)**2 + aimag(fc)**2)
        ! squared bounds
        do r = 1, nm
            q2 = sq(q(r))
            g2 = sys%pamx(r, h)*sq(sys%g(r, h))
            w(r, 1) = g2*q2
            w(r, 2) = g2*sys%pan(r)*nf2
            if (sys%mode == HBM_FREQUENCY) then
                ! (|q| + |v|)^2 <= 2 (|q|^2 + |v|^2)
                w(r, 3) = sys%pamx(r, h)*sq(sys%dg(r, h))*2.0_wp*(q2 + sys%pan(r)*nf2)
            else
                w(r, 3) = g2*sq(sys%qf1(r, h))
            end if
        end do
        t = (PROJ_SKIP/nm)**2*maxval(w, dim=1)
        skip = 0.0_wp
        nuse = 0
        if (.not. all(t < huge(1.0_wp))) then
            nuse = nm
            use = [(r, r=1, nm)]
            return
        end if
        do r = 1, nm
            if (all(w(r, :) <= t)) then
                skip = skip + sqrt(w(r, :))
                cycle
            end if
            nuse = nuse + 1
            use(nuse) = r
        end do

    contains

        !> |z|^2 without the square root
        pure real(wp) function sq(z)
            complex(wp), intent(in) :: z
            sq = real(z, wp)**2 + aimag(z)**2
        end function sq
    end subroutine sel_modes

    !> Whether the modes sel_modes left out are negligible against the terms computed:
    !> skip(k) <= PROJ_SKIP times the largest |A(rows, r) x3(r, k)| over r in use (a few
    !> units of round-off of that term, below the round-off of the sum over all modes).
    !> The columns that do not hold v (g q; -g qf1) had exact bounds: sel_modes's
    !> threshold alone keeps them. Else cond_eval takes every mode.
    logical function proj_safe(sys, h, q, use, v, skip)
        type(hbm_condensed), intent(in) :: sys
        integer(ip), intent(in) :: h, use(:)
        complex(wp), intent(in) :: q(:), v(:)
        real(wp), intent(in) :: skip(3)
        real(wp) :: big(3), a
        integer(ip) :: k, r
        big = 0.0_wp
        do k = 1, size(use)
            r = use(k)
            a = sqrt(sys%pamx(r, h))
            big(2) = max(big(2), a*abs(sys%g(r, h)*v(r)))
            big(3) = max(big(3), a*abs(sys%dg(r, h)*(q(r) - v(r))))
        end do
        proj_safe = skip(2) <= PROJ_SKIP*big(2)
        if (sys%mode == HBM_FREQUENCY) proj_safe = proj_safe .and. skip(3) <= PROJ_SKIP*big(3)
    end function proj_safe

    module procedure project_kept
        real(wp), allocatable :: fr(:, :), vr(:, :)
        integer(ip) :: lo, hi, nr, nm
        lo = sys%kptr(h + 1)
        hi = sys%kptr(h + 2) - 1
        nr = hi - lo + 1
        nm = size(sys%prow, 2)
        v = (0.0_wp, 0.0_wp)
        if (nr <= 0) return
        allocate (fr(nr, 2), vr(nm, 2))
        fr(:, 1) = real(fc(sys%kpt(lo:hi)), wp)
        fr(:, 2) = aimag(fc(sys%kpt(lo:hi)))
        call dgemm('T', 'N', nm, 2, nr, 1.0_wp, sys%prow(lo, 1), size(sys%prow, 1), fr, nr, &
                   0.0_wp, vr, nm)
        v = cmplx(vr(:, 1), vr(:, 2), wp)
    end procedure project_kept

    !> v(use) = A^H fc over the rows T (real modes phr), v zero elsewhere: the columns
    !> use of phr gathered, one product.
    subroutine project_some(sys, fc, use, v)
        type(hbm_condensed), intent(in) :: sys
        complex(wp), intent(in) :: fc(:)
        integer(ip), intent(in) :: use(:)
        complex(wp), intent(out) :: v(:)
        real(wp), allocatable :: pg(:, :), fr(:, :), vr(:, :)
        integer(ip) :: nu, k
        nu = sys%nnl
        k = size(use)
        v = (0.0_wp, 0.0_wp)
        if (k == 0) return
        allocate (fr(nu, 2), vr(k, 2))
        pg = sys%phr(1:nu, use)
        fr(:, 1) = real(fc, wp)
        fr(:, 2) = aimag(fc)
        call dgemm('T', 'N', k, 2, nu, 1.0_wp, pg, nu, fr, nu, 0.0_wp, vr, k)
        v(use) = cmplx(vr(:, 1), vr(:, 2), wp)
    end subroutine project_some

    module procedure rows_some
        real(wp), allocatable :: pk(:, :), xr(:, :), br(:, :)
        integer(ip) :: nu, k, nr, lo, hi
        k = size(x, 2)
        nu = size(use)
        lo = sys%kptr(h + 1)
        hi = sys%kptr(h + 2) - 1
        nr = hi - lo + 1
        b = (0.0_wp, 0.0_wp)
        if (nr <= 0 .or. nu == 0) return
        pk = sys%prow(lo:hi, use)
        allocate (xr(nu, 2*k), br(nr, 2*k))
        xr(:, 1:k) = real(x(use, :), wp)
        xr(:, k + 1:) = aimag(x(use, :))
        call dgemm('N', 'N', nr, 2*k, nu, 1.0_wp, pk, nr, xr, nu, 0.0_wp, br, nr)
        b(sys%kpt(lo:hi), :) = cmplx(br(:, 1:k), br(:, k + 1:), wp)
    end procedure rows_some

    module procedure modal_rows
        real(wp), allocatable :: pk(:, :), xr(:, :), br(:, :)
        complex(wp), allocatable :: zk(:, :), bk(:, :)
        integer(ip) :: nm, k, nr
        nm = size(x, 1)
        k = size(x, 2)
        nr = size(rows)
        b = (0.0_wp, 0.0_wp)
        if (nr == 0) return
        if (allocated(sys%phr)) then
            pk = sys%phr(rows, :)
            allocate (xr(nm, 2*k), br(nr, 2*k))
            xr(:, 1:k) = real(x, wp)
            xr(:, k + 1:) = aimag(x)
            call dgemm('N', 'N', nr, 2*k, nm, 1.0_wp, pk, nr, xr, nm, 0.0_wp, br, nr)
            b(rows, :) = cmplx(br(:, 1:k), br(:, k + 1:), wp)
        else
            zk = sys%psi(rows, :, h)
            allocate (bk(nr, k))
            call zgemm('N', 'N', nr, k, nm, (1.0_wp, 0.0_wp), zk, nr, x, nm, &
                       (0.0_wp, 0.0_wp), bk, nr)
            b(rows, :) = bk
        end if
    end procedure modal_rows
end submodule frirom_hbm_keptrows
