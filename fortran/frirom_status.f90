!> Status codes returned by every frirom routine through `info` (0 = success) and the
!> text that goes with each. Library code never stops: it returns one of these, and a
!> routine that knows more (which element, which argument) also fills `errmsg`.
module frirom_status
    use frirom_kinds, only: ip
    implicit none
    private
    public :: frirom_status_message, frirom_status_code, set_status, failed, itoa
    public :: FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_PARAM, FRIROM_ERR_NONFINITE, &
              FRIROM_ERR_SAMPLES, FRIROM_ERR_ALLOC, FRIROM_ERR_FFTW, FRIROM_ERR_LAPACK, &
              FRIROM_ERR_ARPACK, FRIROM_ERR_NOCONV, FRIROM_ERR_SINGULAR, FRIROM_ERR_LAW, &
              FRIROM_ERR_NOCLOSE, FRIROM_ERR_CONT, FRIROM_ERR_MODEL
    public :: FRIROM_ERR_FACTOR

    ! General codes 1-19; solver codes from 20; reduction codes from 40.
    integer(ip), parameter :: FRIROM_OK = 0
    integer(ip), parameter :: FRIROM_ERR_SIZE = 1
    integer(ip), parameter :: FRIROM_ERR_PARAM = 2
    integer(ip), parameter :: FRIROM_ERR_NONFINITE = 3
    integer(ip), parameter :: FRIROM_ERR_SAMPLES = 4
    integer(ip), parameter :: FRIROM_ERR_ALLOC = 5
    integer(ip), parameter :: FRIROM_ERR_FFTW = 6
    integer(ip), parameter :: FRIROM_ERR_LAPACK = 7
    integer(ip), parameter :: FRIROM_ERR_ARPACK = 8
    integer(ip), parameter :: FRIROM_ERR_NOCONV = 9
    integer(ip), parameter :: FRIROM_ERR_SINGULAR = 10
    integer(ip), parameter :: FRIROM_ERR_LAW = 11
    integer(ip), parameter :: FRIROM_ERR_NOCLOSE = 12
    integer(ip), parameter :: FRIROM_ERR_CONT = 20
    integer(ip), parameter :: FRIROM_ERR_MODEL = 21
    ! Reduction codes.
    integer(ip), parameter :: FRIROM_ERR_FACTOR = 40

contains

    !> The generic text of a status code.
    pure function frirom_status_message(info) result(msg)
        integer(ip), intent(in) :: info  !! status code
        character(len=:), allocatable :: msg
        select case (info)
        case (FRIROM_OK)
            msg = 'success'
        case (FRIROM_ERR_SIZE)
            msg = 'array sizes do not match'
        case (FRIROM_ERR_PARAM)
            msg = 'invalid parameter'
        case (FRIROM_ERR_NONFINITE)
            msg = 'non-finite input (NaN or Inf)'
        case (FRIROM_ERR_SAMPLES)
            msg = 'too few time samples: N must be at least 2H+1'
        case (FRIROM_ERR_ALLOC)
            msg = 'memory allocation failed'
        case (FRIROM_ERR_FFTW)
            msg = 'FFTW could not create a plan'
        case (FRIROM_ERR_LAPACK)
            msg = 'a LAPACK routine failed'
        case (FRIROM_ERR_ARPACK)
            msg = 'an ARPACK routine failed'
        case (FRIROM_ERR_NOCONV)
            msg = 'iteration did not converge'
        case (FRIROM_ERR_SINGULAR)
            msg = 'matrix is singular'
        case (FRIROM_ERR_LAW)
            msg = 'unknown contact law'
        case (FRIROM_ERR_NOCLOSE)
            msg = 'hysteresis cycle did not close within the allowed number of periods'
        case (FRIROM_ERR_CONT)
            msg = 'continuation stopped: the corrector failed at the minimum step'
        case (FRIROM_ERR_MODEL)
            msg = 'inconsistent model data'
        case (FRIROM_ERR_FACTOR)
            msg = 'sparse factorisation failed'
        case default
            msg = 'unknown status code'
        end select
    end function frirom_status_message

    !> The code of a status by its name here ('FRIROM_ERR_CONT', ...), -1 for an unknown
    !> name: callers in other languages look codes up instead of copying them.
    pure function frirom_status_code(name) result(code)
        character(len=*), intent(in) :: name  !! parameter name, as in this module
        integer(ip) :: code
        select case (name)
        case ('FRIROM_OK')
            code = FRIROM_OK
        case ('FRIROM_ERR_SIZE')
            code = FRIROM_ERR_SIZE
        case ('FRIROM_ERR_PARAM')
            code = FRIROM_ERR_PARAM
        case ('FRIROM_ERR_NONFINITE')
            code = FRIROM_ERR_NONFINITE
        case ('FRIROM_ERR_SAMPLES')
            code = FRIROM_ERR_SAMPLES
        case ('FRIROM_ERR_ALLOC')
            code = FRIROM_ERR_ALLOC
        case ('FRIROM_ERR_FFTW')
            code = FRIROM_ERR_FFTW
        case ('FRIROM_ERR_LAPACK')
            code = FRIROM_ERR_LAPACK
        case ('FRIROM_ERR_ARPACK')
            code = FRIROM_ERR_ARPACK
        case ('FRIROM_ERR_NOCONV')
            code = FRIROM_ERR_NOCONV
        case ('FRIROM_ERR_SINGULAR')
            code = FRIROM_ERR_SINGULAR
        case ('FRIROM_ERR_LAW')
            code = FRIROM_ERR_LAW
        case ('FRIROM_ERR_NOCLOSE')
            code = FRIROM_ERR_NOCLOSE
        case ('FRIROM_ERR_CONT')
            code = FRIROM_ERR_CONT
        case ('FRIROM_ERR_MODEL')
            code = FRIROM_ERR_MODEL
        case ('FRIROM_ERR_FACTOR')
            code = FRIROM_ERR_FACTOR
        case default
            code = -1
        end select
    end function frirom_status_code

    !> Set `info` and, when the caller passed one, a message naming what went wrong.
    pure subroutine set_status(info, code, errmsg, detail)
        integer(ip), intent(out) :: info                    !! status code to return
        integer(ip), intent(in) :: code                     !! one of FRIROM_*
        character(len=*), intent(inout), optional :: errmsg !! message for the caller
        character(len=*), intent(in) :: detail              !! what, where, expected what
        info = code
        if (present(errmsg)) errmsg = frirom_status_message(code)//': '//detail
    end subroutine set_status

    !> The one form of an argument check: where `bad`, set_status(info, code, errmsg,
    !> detail) and true, so that `if (failed(...)) return`; else false, info untouched.
    logical function failed(bad, info, code, errmsg, detail)
        logical, intent(in) :: bad                          !! the check did not pass
        integer(ip), intent(inout) :: info
        integer(ip), intent(in) :: code
        character(len=*), intent(inout), optional :: errmsg
        character(len=*), intent(in) :: detail
        failed = bad
        if (bad) call set_status(info, code, errmsg, detail)
    end function failed

    !> An integer as text without blanks, for messages (trim the result).
    pure function itoa(i) result(t)
        integer(ip), intent(in) :: i
        character(len=24) :: t
        write (t, '(i0)') i
    end function itoa
end module frirom_status
