/* A Windows program that binds gts.dll at run time, as C#, VB6 and Delphi programs do:
 * LoadLibrary, then GetProcAddress by the undecorated names the vendor's DLL exports.
 * Prints `key value` lines the test reads. */
#include <stdio.h>
#include <windef.h>
#include <libloaderapi.h> /* LoadLibraryA, GetProcAddress */

typedef short(__stdcall *open_fn)(short, short);
typedef short(__stdcall *void_fn)(void);
typedef short(__stdcall *sts_fn)(short, long *, short, unsigned long *);
typedef short(__stdcall *raw_fn)(unsigned short, unsigned short, unsigned char *);
typedef short(__stdcall *err_fn)(char *, short);

int main(void)
{
    HMODULE h = LoadLibraryA("gts.dll");
    printf("loaded %d\n", h != NULL);
    if (!h)
        return 1;
    open_fn open = (open_fn)(void (*)(void))GetProcAddress(h, "GT_Open");
    void_fn close = (void_fn)(void (*)(void))GetProcAddress(h, "GT_Close");
    sts_fn sts = (sts_fn)(void (*)(void))GetProcAddress(h, "GT_GetSts");
    raw_fn raw = (raw_fn)(void (*)(void))GetProcAddress(h, "GT_GetEcatRawData");
    err_fn why = (err_fn)(void (*)(void))GetProcAddress(h, "GTE_GetLastError");
    printf("found %d\n", open && close && sts && raw && why);
    printf("decorated %d\n", GetProcAddress(h, "_GT_Open@4") != NULL);
    if (!(open && close && sts && raw && why))
        return 1;
    printf("open %d\n", open(0, 1));
    long s = -1;
    printf("sts %d\n", sts(1, &s, 1, NULL));
    printf("sts_value_set %d\n", s != -1);
    unsigned char buf[2] = {0, 0};
    printf("raw %d\n", raw(36, 2, buf));
    printf("raw_past_end %d\n", raw(60000, 2, buf));
    char text[300];
    why(text, sizeof text);
    printf("raw_past_end_reason %s\n", text);
    printf("close %d\n", close());
    printf("done 1\n");
    return 0;
}
