/* gtecat_vendor.h - what a Googol vendor header needs to compile unchanged on Linux.
 *
 * `gtecat lib --cflags` force-includes this file (-include), so a program that includes the
 * vendor's own gts.h, as it ships for Windows, compiles with gcc/clang and links against
 * libgts: the vendor header writes `#define GT_API extern "C" short __stdcall`, passes
 * NULL as a default argument without including <stddef.h>, and some versions name Windows
 * types.  Nothing here is needed by gtecat's own gts.h.  Define GTECAT_NO_WIN_TYPES to
 * leave the Windows type names out (a program that defines them itself).
 */
#ifndef GTECAT_VENDOR_H
#define GTECAT_VENDOR_H

#include <stddef.h>

#if !defined(_WIN32)

/* calling conventions: one convention on x86-64 Linux */
#ifndef __stdcall
#define __stdcall
#endif
#ifndef __cdecl
#define __cdecl
#endif
#ifndef WINAPI
#define WINAPI
#endif

#ifndef GTECAT_NO_WIN_TYPES
/* the Windows names with their Windows sizes (LONG and DWORD are 32 bits there) */
typedef int BOOL;
typedef unsigned char BYTE;
typedef unsigned char UCHAR;
typedef unsigned short WORD;
typedef unsigned short USHORT;
typedef unsigned int DWORD;
typedef unsigned int UINT;
typedef int INT;
typedef int LONG;
typedef unsigned int ULONG;
typedef signed char INT8;
typedef unsigned char UINT8;
typedef short INT16;
typedef unsigned short UINT16;
typedef int INT32;
typedef unsigned int UINT32;
typedef void *HANDLE;
typedef void *LPVOID;
#ifndef TRUE
#define TRUE 1
#endif
#ifndef FALSE
#define FALSE 0
#endif
#endif /* GTECAT_NO_WIN_TYPES */

#endif /* !_WIN32 */

#endif /* GTECAT_VENDOR_H */
