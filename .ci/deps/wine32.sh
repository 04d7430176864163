# 32-bit Wine, for the x86 gts.dll's programs (tests/gtecat/native/test_windows.py); its
# packages are of the i386 architecture, which PREPARE adds first
PREPARE="dpkg --add-architecture i386"
DEBS="wine32:i386"
