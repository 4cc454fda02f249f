!> Checks shared by the Fortran test programs. `check` prints and counts each failed
!> condition and lets the program go on, so that one run reports every failure;
!> `check_done` ends the program: a line saying all checks passed, or `error stop` with
!> the number of failures.
module frirom_check
    use, intrinsic :: iso_fortran_env, only: output_unit
    use frirom_kinds, only: ip
    implicit none
    private
    public :: check, check_done, fixed_seed

    integer(ip) :: nfail = 0  !! failed checks so far in this program

contains

    !> Seed random_number with a fixed sequence, so a test program draws the same numbers
    !> on every run (random_seed() without arguments takes them from the OS: a random
    !> point may then land on a contact-state switch in one run out of many).
    subroutine fixed_seed(base)
        integer, intent(in) :: base            !! any integer; the same base, the same draws
        integer :: n, i
        integer, allocatable :: seed(:)
        call random_seed(size=n)
        allocate (seed(n))
        seed = [(base + 7919*i, i=1, n)]
        call random_seed(put=seed)
    end subroutine fixed_seed

    !> Record one check: when `ok` is false, print what failed and count it.
    subroutine check(ok, what)
        logical, intent(in) :: ok              !! the condition that must hold
        character(len=*), intent(in) :: what   !! what it checks
        if (.not. ok) then
            nfail = nfail + 1
            print '(2a)', 'FAILED: ', what
            flush (output_unit)
        end if
    end subroutine check

    !> End a test program: `error stop` with a message when any check failed.
    subroutine check_done(program_name)
        character(len=*), intent(in) :: program_name  !! e.g. 'test_banded'
        character(len=200) :: text
        if (nfail > 0) then
            write (text, '(a,a,i0,a)') program_name, ': ', nfail, ' check(s) failed'
            error stop trim(text)
        end if
        print '(2a)', program_name, ': all checks passed'
    end subroutine check_done
end module frirom_check
