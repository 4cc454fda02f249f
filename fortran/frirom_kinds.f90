!> Kinds used everywhere in frirom: working precision and integer kind.
module frirom_kinds
    use, intrinsic :: iso_fortran_env, only: real64, int32
    implicit none
    private
    public :: wp, ip

    integer, parameter :: wp = real64  !! working precision for all reals
    integer, parameter :: ip = int32   !! integer kind of sizes, indices and status codes
end module frirom_kinds
