# gts.dll for Windows and its tests under Wine (tests/gtecat/native/test_windows.py): the
# mingw-w64 cross compilers (C and C++, 64- and 32-bit) and 64-bit Wine (wine32.sh: 32-bit)
DEBS="gcc-mingw-w64-x86-64 gcc-mingw-w64-i686 g++-mingw-w64-x86-64 g++-mingw-w64-i686 wine wine64"
