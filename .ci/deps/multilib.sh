# gtecat lib --m32 (a 32-bit program against the vendor's own header) and its test
# (tests/gtecat/native/test_m32.py): the 32-bit C and C++ libraries
DEBS="gcc-multilib g++-multilib"
