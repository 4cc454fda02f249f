!> Sparse complex symmetric solves by MUMPS (sequential, zmumps): the dynamic stiffness
!> D_h = K + i h w C - (h w)^2 M of a large unreduced model, factorised with a fill-reducing
!> ordering instead of a full band (frirom_hbm_condensed's receptances).
module frirom_zsparse
    use frirom_kinds, only: wp, ip
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_ALLOC, FRIROM_ERR_FACTOR, set_status
    implicit none
    private
    include 'zmumps_struc.h'
    public :: zsparse_solve, mumps_status

contains

    !> B := A^-1 B for a complex symmetric sparse A given by one triangle in coordinate
    !> form (1-based; duplicates are summed). The factor is made and released here
    !> (LDL^T, MUMPS SYM = 2, automatic ordering), so nothing is held between calls.
    subroutine zsparse_solve(n, irn, jcn, a, b, info, errmsg)
        integer(ip), intent(in) :: n
        integer(ip), intent(in) :: irn(:), jcn(:)       !! (nz) rows, columns
        complex(wp), intent(in) :: a(:)                 !! (nz) values
        complex(wp), intent(inout), target, contiguous :: b(:, :)  !! (n, nrhs)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        type(zmumps_struc) :: m
        integer :: nz, stat, try
        info = FRIROM_OK
        nz = size(irn)
        m%comm = 0
        m%par = 1
        m%sym = 2
        m%job = -1
        call zmumps(m)
        if (m%infog(1) < 0) then
            call mumps_status('zmumps', m%infog(1), m%infog(2), 'init', info, errmsg)
            return
        end if
        m%icntl(1:4) = [-1, -1, -1, 0]   ! silent
        m%icntl(7) = 7                   ! automatic ordering
        m%n = n
        m%nnz = int(nz, kind=8)
        allocate (m%irn(nz), m%jcn(nz), m%a(nz), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'zmumps: matrix entries')
        else
            m%irn = irn
            m%jcn = jcn
            m%a = a
            do try = 1, 3
                m%job = 4                    ! analysis + factorisation
                call zmumps(m)
                if (.not. any(m%infog(1) == [-8, -9, -11, -12, -14, -15])) exit
                m%icntl(14) = 2*max(m%icntl(14), 20)   ! more working memory, retry
            end do
            if (m%infog(1) < 0) then
                call mumps_status('zmumps', m%infog(1), m%infog(2), 'factorisation', info, &
                                  errmsg)
            else
                m%rhs(1:size(b)) => b
                m%nrhs = size(b, 2)
                m%lrhs = n
                m%job = 3
                call zmumps(m)
                nullify (m%rhs)
                if (m%infog(1) < 0) call mumps_status('zmumps', m%infog(1), m%infog(2), &
                                                      'solve', info, errmsg)
            end if
        end if
        if (associated(m%irn)) deallocate (m%irn)
        if (associated(m%jcn)) deallocate (m%jcn)
        if (associated(m%a)) deallocate (m%a)
        m%job = -2
        call zmumps(m)

    end subroutine zsparse_solve

    !> A MUMPS failure (INFOG(1) < 0) of `solver` ('dmumps', 'zmumps') at `stage` as a
    !> frirom status: out of memory (-13) or a failed factorisation.
    subroutine mumps_status(solver, infog1, infog2, stage, info, errmsg)
        character(len=*), intent(in) :: solver, stage
        integer, intent(in) :: infog1, infog2
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg
        character(len=200) :: buf
        write (buf, '(a,a,a,a,a,i0,a,i0,a)') solver, ' (', stage, '): INFOG(1) = ', infog1, &
            ', INFOG(2) = ', infog2, ' (see the MUMPS user guide, error codes)'
        if (infog1 == -13) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, trim(buf))
        else
            call set_status(info, FRIROM_ERR_FACTOR, errmsg, trim(buf))
        end if
    end subroutine mumps_status
end module frirom_zsparse
