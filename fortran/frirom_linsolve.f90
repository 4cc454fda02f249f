!> Dense linear solves for a sequence of nearby matrices A: an LU held from an earlier A
!> (double precision, or single precision with a Woodbury correction for a low-rank
!> change since it was made) and a restarted flexible GMRES on the current A,
!> right-preconditioned by it. The matrix and the preconditioner are the caller's (an
!> extension of lin_operator); the factors and workspaces live in derived types the
!> caller owns (held_lu, gmres_work) and are kept from call to call.
module frirom_linsolve
    use, intrinsic :: iso_fortran_env, only: real32
    use frirom_kinds, only: wp, ip
    use frirom_lapack, only: dgemm, dgemv, sgetrf, sgetrs, dgetrf, dgetrs
    implicit none
    private
    public :: lin_operator, gmres_work, woodbury, held_lu, fgmres, held_lu_factor, &
              held_lu_apply, woodbury_reset, woodbury_alloc, woodbury_finish, &
              woodbury_prepare, GMRES_RESTART

    !> GMRES restart length (Krylov basis size)
    integer(ip), parameter :: GMRES_RESTART = 30

    !> A square matrix A and a preconditioner M ~ A for fgmres.
    type, abstract :: lin_operator
    contains
        !> y = A x
        procedure(apply_iface), deferred :: apply
        !> w := M^-1 w, every column (one pass for all of them)
        procedure(precond_iface), deferred :: precond
    end type lin_operator

    abstract interface
        subroutine apply_iface(this, x, y)
            import :: lin_operator, wp
            class(lin_operator), intent(inout) :: this
            real(wp), intent(in) :: x(:)        !! (n)
            real(wp), intent(out) :: y(:)       !! (n)
        end subroutine apply_iface

        subroutine precond_iface(this, w)
            import :: lin_operator, wp
            class(lin_operator), intent(inout) :: this
            real(wp), intent(inout) :: w(:, :)  !! (n, columns)
        end subroutine precond_iface
    end interface

    !> fgmres's Krylov bases, kept between calls: v (n, restart+1, columns) and the
    !> preconditioned directions z (n, restart, columns).
    type :: gmres_work
        real(wp), allocatable :: v(:, :, :), z(:, :, :)
    end type gmres_work

    !> Woodbury correction of a single-precision held LU for A = A0 + U D V, a change of
    !> rank m since A0 was factorised: D block diagonal, a 2 x 2 block [dr di; -di dr] for
    !> each complex d_k (a complex factor acting on a cosine and a sine row), so that
    !> A^-1 = A0^-1 - W (I + D S)^-1 D V A0^-1 with W = A0^-1 U, S = V W.
    type :: woodbury
        logical :: ok = .false.                  !! w, v, s hold a valid correction
        real(wp) :: at = -1.0_wp                 !! the caller's key l was prepared for
        real(wp) :: at0 = -1.0_wp                !! the key of A0 itself (D = 0 there)
        real(wp), allocatable :: w(:, :)         !! (n, m) U, then W = A0^-1 U
        real(wp), allocatable :: v(:, :)         !! (m, n) V
        real(wp), allocatable :: s(:, :)         !! (m, m) S = V W
        real(wp), allocatable :: l(:, :)         !! (m, m) LU of I + D S
        integer(ip), allocatable :: p(:)         !! (m) its pivots
        real(wp), allocatable :: t(:, :)         !! (m, 2 columns) work, kept
    end type woodbury

    !> An LU held to solve with or precondition later matrices: the double factors stay in
    !> the caller's matrix (factorised in place, no second n x n copy); single-precision
    !> factors are kept here (half the flops of the LU and half the memory traffic of each
    !> triangular solve), with an optional Woodbury correction.
    type :: held_lu
        logical :: single = .false.              !! the factors are lus (else the caller's)
        real(real32), allocatable :: lus(:, :)   !! (n, n) single-precision factors
        integer(ip), allocatable :: ipiv(:)      !! (n) pivots of either
        real(real32), allocatable :: ws(:, :)    !! (n, columns) work of the single solves
        type(woodbury) :: wb
    end type held_lu

contains

    !> LU of a (n x n): in place in double precision, or of a single-precision copy into
    !> lu%lus (single). linfo: LAPACK's info; stat /= 0: lus could not be allocated (then
    !> nothing else is done).
    subroutine held_lu_factor(lu, a, single, linfo, stat)
        type(held_lu), intent(inout) :: lu
        real(wp), intent(inout), contiguous :: a(:, :)   !! (n, n) A; its factors if double
        logical, intent(in) :: single
        integer(ip), intent(out) :: linfo, stat
        integer(ip) :: n
        n = size(a, 1)
        stat = 0
        linfo = 0
        if (single .and. .not. allocated(lu%lus)) then
            allocate (lu%lus(n, n), stat=stat)
            if (stat /= 0) return
        end if
        if (single) then
            lu%lus = real(a, real32)
            call sgetrf(n, n, lu%lus, n, lu%ipiv, linfo)
        else
            call dgetrf(n, n, a, n, lu%ipiv, linfo)
        end if
        lu%single = single
    end subroutine held_lu_factor

    !> w := M^-1 w for the LU held (lus, or the double factors a), all columns at once,
    !> with the Woodbury correction for the change d when it was prepared for key
    !> (woodbury_prepare) and key is not A0's.
    subroutine held_lu_apply(lu, a, w, key, d)
        type(held_lu), intent(inout) :: lu
        real(wp), intent(in), contiguous :: a(:, :)  !! (n, n) double factors (not single)
        real(wp), intent(inout) :: w(:, :)           !! (n, columns)
        real(wp), intent(in) :: key
        !> (m/2) the change d_k of the correction's factors at key (as prepared); none:
        !> no correction
        complex(wp), intent(in), optional :: d(:)
        real(real32), allocatable :: ws(:, :)
        real(wp), allocatable :: t(:, :)
        integer(ip) :: n, linfo, m, k, nr
        n = size(lu%ipiv)
        nr = size(w, 2)
        if (lu%single) then
            call move_alloc(lu%ws, ws)
            if (allocated(ws)) then
                if (size(ws, 1) /= n .or. size(ws, 2) < nr) deallocate (ws)
            end if
            if (.not. allocated(ws)) allocate (ws(n, nr))
            ws(:, 1:nr) = real(w, real32)
            call sgetrs('N', n, nr, lu%lus, n, lu%ipiv, ws, n, linfo)
            w = real(ws(:, 1:nr), wp)
            call move_alloc(ws, lu%ws)
            if (.not. present(d)) return
            if (lu%wb%ok .and. lu%wb%at == key .and. key /= lu%wb%at0) then
                ! w -= W (I + D S)^-1 D V w; t(:, 1:nr) = V w, t(:, nr+1:) = D V w
                m = size(lu%wb%s, 1)
                call move_alloc(lu%wb%t, t)
                if (allocated(t)) then
                    if (size(t, 1) /= m .or. size(t, 2) < 2*nr) deallocate (t)
                end if
                if (.not. allocated(t)) allocate (t(m, 2*nr))
                call dgemm('N', 'N', m, nr, n, 1.0_wp, lu%wb%v, m, w, size(w, 1), &
                           0.0_wp, t, m)
                associate (t1 => t(:, 1:nr), t2 => t(:, nr + 1:2*nr))
                    do k = 1, m/2
                        t2(2*k - 1, :) = real(d(k), wp)*t1(2*k - 1, :) + aimag(d(k))*t1(2*k, :)
                        t2(2*k, :) = -aimag(d(k))*t1(2*k - 1, :) + real(d(k), wp)*t1(2*k, :)
                    end do
                end associate
                call dgetrs('N', m, nr, lu%wb%l, m, lu%wb%p, t(1, nr + 1), m, linfo)
                call dgemm('N', 'N', n, nr, m, -1.0_wp, lu%wb%w, n, t(1, nr + 1), m, 1.0_wp, &
                           w, size(w, 1))
                call move_alloc(t, lu%wb%t)
            end if
        else
            call dgetrs('N', n, nr, a, n, lu%ipiv, w, size(w, 1), linfo)
        end if
    end subroutine held_lu_apply

    !> No correction (its arrays freed) until the next woodbury_finish, for an LU made at
    !> key at0.
    subroutine woodbury_reset(lu, at0)
        type(held_lu), intent(inout) :: lu
        real(wp), intent(in) :: at0
        lu%wb%ok = .false.
        lu%wb%at = -1.0_wp
        lu%wb%at0 = at0
        if (allocated(lu%wb%w)) deallocate (lu%wb%w, lu%wb%v, lu%wb%s, lu%wb%l, lu%wb%p)
    end subroutine woodbury_reset

    !> Space for a correction of rank m (n unknowns): U into wb%w and V into wb%v, for the
    !> caller to fill before woodbury_finish. stat /= 0: none allocated.
    subroutine woodbury_alloc(lu, n, m, stat)
        type(held_lu), intent(inout) :: lu
        integer(ip), intent(in) :: n, m
        integer(ip), intent(out) :: stat
        if (allocated(lu%wb%w)) deallocate (lu%wb%w, lu%wb%v, lu%wb%s, lu%wb%l, lu%wb%p)
        allocate (lu%wb%w(n, m), lu%wb%v(m, n), lu%wb%s(m, m), lu%wb%l(m, m), lu%wb%p(m), &
                  stat=stat)
        if (stat /= 0) then
            if (allocated(lu%wb%w)) deallocate (lu%wb%w, lu%wb%v, lu%wb%s, lu%wb%l, lu%wb%p)
        end if
    end subroutine woodbury_alloc

    !> W = A0^-1 U by the single LU and S = V W, with U and V in wb%w and wb%v; the
    !> correction is valid (wb%ok) when the solve succeeds.
    subroutine woodbury_finish(lu)
        type(held_lu), intent(inout) :: lu
        real(real32), allocatable :: ws(:, :)
        integer(ip) :: n, m, linfo
        n = size(lu%wb%w, 1)
        m = size(lu%wb%w, 2)
        allocate (ws(n, m))
        ws = real(lu%wb%w, real32)
        call sgetrs('N', n, m, lu%lus, n, lu%ipiv, ws, n, linfo)
        lu%wb%w = real(ws, wp)
        call dgemm('N', 'N', m, m, n, 1.0_wp, lu%wb%v, m, lu%wb%w, n, 0.0_wp, lu%wb%s, m)
        lu%wb%ok = linfo == 0
    end subroutine woodbury_finish

    !> The small LU of I + D S for the change d at key, unless it is prepared for key
    !> already, key is A0's (D = 0) or there is no single LU with a valid correction.
    subroutine woodbury_prepare(lu, key, d)
        type(held_lu), intent(inout) :: lu
        real(wp), intent(in) :: key
        complex(wp), intent(in) :: d(:)          !! (m/2) the factors' change at key
        integer(ip) :: k, m, i, linfo
        real(wp) :: dr, di
        if (.not. (lu%wb%ok .and. lu%single) .or. lu%wb%at == key) return
        lu%wb%at = key
        if (key == lu%wb%at0) return
        m = size(lu%wb%s, 1)
        do k = 1, m/2
            dr = real(d(k), wp)
            di = aimag(d(k))
            i = 2*k - 1
            lu%wb%l(i, :) = dr*lu%wb%s(i, :) + di*lu%wb%s(i + 1, :)
            lu%wb%l(i + 1, :) = -di*lu%wb%s(i, :) + dr*lu%wb%s(i + 1, :)
        end do
        do i = 1, m
            lu%wb%l(i, i) = lu%wb%l(i, i) + 1.0_wp
        end do
        call dgetrf(m, m, lu%wb%l, m, lu%wb%p, linfo)
        if (linfo /= 0) lu%wb%ok = .false.
    end subroutine woodbury_prepare

    !> b := A^-1 b, column by column, by restarted flexible GMRES on op's A,
    !> right-preconditioned by op's M (the preconditioned directions Z are kept, so
    !> x = x0 + Z y is exact for an inexact M), from x0 = M^-1 b, to a residual of tol |b|.
    !> The columns iterate in lockstep: one op%precond per iteration for all of them.
    !> its: the iterations summed over the columns; ok false (b unchanged) when a column
    !> needs more than maxit.
    subroutine fgmres(op, b, tol, maxit, work, its, ok)
        class(lin_operator), intent(inout) :: op
        real(wp), intent(inout) :: b(:, :)       !! (n, columns)
        real(wp), intent(in) :: tol
        integer(ip), intent(in) :: maxit
        type(gmres_work), intent(inout) :: work
        integer(ip), intent(out) :: its
        logical, intent(out) :: ok
        integer(ip), parameter :: m = GMRES_RESTART
        real(wp), allocatable :: v(:, :, :), z(:, :, :), hh(:, :, :), cs(:, :), sn(:, :), &
                                 gv(:, :), x(:, :), r(:), w(:, :), bn(:)
        real(wp) :: beta, tmp
        integer(ip) :: n, nb, c, q, na, j, i
        integer(ip), allocatable :: itc(:), kk(:), ac(:)
        logical, allocatable :: done(:), act(:)
        logical :: slow
        n = size(b, 1)
        nb = size(b, 2)
        ! the bases: kept in work from call to call, lent here
        call move_alloc(work%v, v)
        call move_alloc(work%z, z)
        if (allocated(v)) then
            if (size(v, 1) /= n .or. size(v, 3) < nb) deallocate (v, z)
        end if
        if (.not. allocated(v)) allocate (v(n, m + 1, nb), z(n, m, nb))
        allocate (hh(m + 1, m, nb), cs(m, nb), sn(m, nb), gv(m + 1, nb), r(n), w(n, nb), &
                  bn(nb), itc(nb), kk(nb), ac(nb), done(nb), act(nb))
        its = 0
        ok = .false.
        slow = .false.
        itc = 0
        do c = 1, nb
            bn(c) = norm2(b(:, c))
        end do
        done = bn == 0.0_wp
        x = b
        call op%precond(x)
        restarts: do
            ! r = b - A x per open column
            act = .false.
            do c = 1, nb
                if (done(c)) cycle
                call op%apply(x(:, c), r)
                r = b(:, c) - r
                beta = norm2(r)
                if (beta <= tol*bn(c)) then
                    done(c) = .true.
                    cycle
                end if
                if (itc(c) >= maxit) then
                    slow = .true.           ! too slow: b unchanged
                    exit restarts
                end if
                v(:, 1, c) = r/beta
                gv(:, c) = 0.0_wp
                gv(1, c) = beta
                act(c) = .true.
            end do
            if (all(done)) exit
            kk = 0
            do j = 1, m
                na = 0
                do c = 1, nb
                    if (.not. act(c)) cycle
                    na = na + 1
                    ac(na) = c
                    w(:, na) = v(:, j, c)
                end do
                if (na == 0) exit
                call op%precond(w(:, 1:na))
                do q = 1, na
                    c = ac(q)
                    itc(c) = itc(c) + 1
                    kk(c) = j
                    ! v_j+1 = A M^-1 v_j, orthogonalised (modified Gram-Schmidt)
                    z(:, j, c) = w(:, q)
                    call op%apply(z(:, j, c), v(:, j + 1, c))
                    do i = 1, j
                        hh(i, j, c) = dot_product(v(:, i, c), v(:, j + 1, c))
                        v(:, j + 1, c) = v(:, j + 1, c) - hh(i, j, c)*v(:, i, c)
                    end do
                    hh(j + 1, j, c) = norm2(v(:, j + 1, c))
                    if (hh(j + 1, j, c) > 0.0_wp) v(:, j + 1, c) = v(:, j + 1, c)/hh(j + 1, j, c)
                    do i = 1, j - 1
                        tmp = cs(i, c)*hh(i, j, c) + sn(i, c)*hh(i + 1, j, c)
                        hh(i + 1, j, c) = -sn(i, c)*hh(i, j, c) + cs(i, c)*hh(i + 1, j, c)
                        hh(i, j, c) = tmp
                    end do
                    tmp = hypot(hh(j, j, c), hh(j + 1, j, c))
                    if (tmp == 0.0_wp) then
                        ! breakdown: column j adds nothing; solve with the first j - 1
                        kk(c) = j - 1
                        act(c) = .false.
                        cycle
                    end if
                    cs(j, c) = hh(j, j, c)/tmp
                    sn(j, c) = hh(j + 1, j, c)/tmp
                    hh(j, j, c) = tmp
                    hh(j + 1, j, c) = 0.0_wp
                    gv(j + 1, c) = -sn(j, c)*gv(j, c)
                    gv(j, c) = cs(j, c)*gv(j, c)
                    if (abs(gv(j + 1, c)) <= 0.1_wp*tol*bn(c) .or. itc(c) >= maxit) &
                        act(c) = .false.
                end do
            end do
            ! x += Z y, H y = g (upper triangular)
            do c = 1, nb
                if (done(c) .or. kk(c) == 0) cycle
                do i = kk(c), 1, -1
                    gv(i, c) = (gv(i, c) - dot_product(hh(i, i + 1:kk(c), c), &
                                                       gv(i + 1:kk(c), c)))/hh(i, i, c)
                end do
                call dgemv('N', n, kk(c), 1.0_wp, z(:, :, c), n, gv(:, c), 1, 1.0_wp, &
                           x(:, c), 1)
            end do
        end do restarts
        its = sum(itc)
        call move_alloc(v, work%v)
        call move_alloc(z, work%z)
        if (slow) return
        b = x
        ok = .true.
    end subroutine fgmres
end module frirom_linsolve
