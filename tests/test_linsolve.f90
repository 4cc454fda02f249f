!> frirom_linsolve: the held LU (double and single precision), its Woodbury correction
!> for a low-rank change, and flexible GMRES preconditioned by an LU of a nearby matrix,
!> on random well-conditioned dense matrices (residuals computed here by matmul,
!> independently of the solver).
module linsolve_test_op
    use frirom_kinds, only: wp, ip
    use frirom_linsolve, only: lin_operator, held_lu, held_lu_apply
    implicit none
    private
    public :: dense_op

    !> A dense A, preconditioned by the held LU of a nearby matrix (factors in f, or
    !> single-precision ones in lu), with the Woodbury change d at key when given.
    type, extends(lin_operator) :: dense_op
        real(wp), allocatable :: a(:, :), f(:, :)
        type(held_lu) :: lu
        real(wp) :: key = 0.0_wp
        complex(wp), allocatable :: d(:)
        integer(ip) :: nprec = 0              !! precond calls
    contains
        procedure :: apply => dense_apply
        procedure :: precond => dense_precond
    end type dense_op

contains

    subroutine dense_apply(this, x, y)
        class(dense_op), intent(inout) :: this
        real(wp), intent(in) :: x(:)
        real(wp), intent(out) :: y(:)
        y = matmul(this%a, x)
    end subroutine dense_apply

    subroutine dense_precond(this, w)
        class(dense_op), intent(inout) :: this
        real(wp), intent(inout) :: w(:, :)
        this%nprec = this%nprec + 1
        if (allocated(this%d)) then
            call held_lu_apply(this%lu, this%f, w, this%key, this%d)
        else
            call held_lu_apply(this%lu, this%f, w, this%key)
        end if
    end subroutine dense_precond
end module linsolve_test_op

program test_linsolve
    use frirom_kinds, only: wp, ip
    use frirom_linsolve, only: gmres_work, fgmres, held_lu_factor, held_lu_apply, &
                               woodbury_reset, woodbury_alloc, woodbury_finish, &
                               woodbury_prepare
    use linsolve_test_op, only: dense_op
    use frirom_check, only: check, check_done, fixed_seed
    implicit none
    integer(ip), parameter :: n = 40, nb = 3, np = 3
    real(wp) :: a0(n, n), e(n, n), b(n, nb), x(n, nb), u(n, 2*np), v(2*np, n), dm(2*np, 2*np)
    real(wp) :: a1(n, n), x0(n, nb), err1, err0
    complex(wp) :: d(np)
    type(dense_op) :: op
    type(gmres_work) :: work
    integer(ip) :: linfo, stat, its, k, c
    logical :: ok

    call fixed_seed(31)
    call random_number(a0)
    a0 = a0 - 0.5_wp
    do k = 1, n
        a0(k, k) = a0(k, k) + real(n, wp)/4.0_wp
    end do
    call random_number(e)
    e = 0.1_wp*(e - 0.5_wp)
    call random_number(b)

    ! the double LU held: A0 x = b to round-off, in place of the caller's matrix
    op%f = a0
    allocate (op%lu%ipiv(n))
    call held_lu_factor(op%lu, op%f, .false., linfo, stat)
    call check(linfo == 0 .and. stat == 0 .and. .not. op%lu%single, 'double held LU')
    x = b
    call held_lu_apply(op%lu, op%f, x, 0.0_wp)
    call check(maxval(abs(matmul(a0, x) - b)) <= 1.0e-13_wp*maxval(abs(b))*n, &
               'double held LU solves A0 x = b')

    ! GMRES on A = A0 + E preconditioned by the LU of A0, three columns in lockstep
    op%a = a0 + e
    x = b
    call fgmres(op, x, 1.0e-11_wp, 40_ip, work, its, ok)
    call check(ok, 'fgmres converges on A0 + E')
    do c = 1, nb
        call check(norm2(matmul(op%a, x(:, c)) - b(:, c)) <= 1.0e-11_wp*norm2(b(:, c)), &
                   'fgmres residual below tol |b|')
    end do
    call check(its >= nb .and. its <= 40*nb, 'fgmres iterations counted per column')
    call check(op%nprec <= its/nb + 2, 'one preconditioner call per iteration, all columns')
    ! too few iterations: b is left as it was
    x = b
    call fgmres(op, x, 1.0e-15_wp, 1_ip, work, its, ok)
    call check(.not. ok .and. all(x == b), 'fgmres leaves b unchanged when too slow')

    ! the single-precision LU held: a solve to single precision, GMRES to double
    op%f = a0
    call held_lu_factor(op%lu, op%f, .true., linfo, stat)
    call check(linfo == 0 .and. stat == 0 .and. op%lu%single .and. all(op%f == a0), &
               'single held LU leaves the caller''s matrix')
    x = b
    call held_lu_apply(op%lu, op%f, x, 0.0_wp)
    err0 = maxval(abs(matmul(a0, x) - b))/maxval(abs(b))
    call check(err0 < 1.0e-4_wp .and. err0 > 1.0e-12_wp, 'single held LU: single precision')
    op%a = a0
    x = b
    call fgmres(op, x, 1.0e-11_wp, 12_ip, work, its, ok)
    call check(ok .and. norm2(matmul(a0, x(:, 1)) - b(:, 1)) <= 1.0e-11_wp*norm2(b(:, 1)), &
               'fgmres to double precision on a single LU')

    ! Woodbury: A1 = A0 + U D V (np complex factors on (cos, sin) pairs), its residual
    ! against the one of the uncorrected LU
    call random_number(u)
    call random_number(v)
    u = u - 0.5_wp
    v = 0.3_wp*(v - 0.5_wp)
    d = [(cmplx(0.2_wp*k, -0.1_wp*k, wp), k=1, np)]
    dm = 0.0_wp
    do k = 1, np
        dm(2*k - 1:2*k, 2*k - 1:2*k) = reshape([real(d(k), wp), -aimag(d(k)), aimag(d(k)), &
                                                real(d(k), wp)], [2, 2])
    end do
    a1 = a0 + matmul(u, matmul(dm, v))
    call woodbury_reset(op%lu, 0.0_wp)
    call woodbury_alloc(op%lu, n, 2*np, stat)
    call check(stat == 0, 'woodbury_alloc')
    op%lu%wb%w = u
    op%lu%wb%v = v
    call woodbury_finish(op%lu)
    call check(op%lu%wb%ok, 'woodbury_finish')
    call woodbury_prepare(op%lu, 1.0_wp, d)
    x = b
    call held_lu_apply(op%lu, op%f, x, 1.0_wp, d)
    err1 = maxval(abs(matmul(a1, x) - b))/maxval(abs(b))
    x0 = b
    call held_lu_apply(op%lu, op%f, x0, 1.0_wp)
    err0 = maxval(abs(matmul(a1, x0) - b))/maxval(abs(b))
    call check(err1 < 1.0e-4_wp .and. err0 > 1.0e2_wp*err1, &
               'Woodbury correction solves A0 + U D V to single precision')
    ! at A0's own key no correction is applied
    call woodbury_prepare(op%lu, 0.0_wp, d)
    x = b
    call held_lu_apply(op%lu, op%f, x, 0.0_wp, d)
    call check(all(x == x0), 'no correction at the key of A0')
    ! GMRES on A1 with the corrected single LU: few iterations
    call woodbury_prepare(op%lu, 1.0_wp, d)
    op%key = 1.0_wp
    op%d = d
    op%a = a1
    x = b
    call fgmres(op, x, 1.0e-11_wp, 12_ip, work, its, ok)
    call check(ok .and. maxval(abs(matmul(a1, x) - b)) <= 1.0e-10_wp*maxval(abs(b)), &
               'fgmres on A0 + U D V with the corrected single LU')
    call check_done('test_linsolve')
end program test_linsolve
