// A smart-home routine as the vendor's demo writes it, compiled against a vendor-style header
// whose structures hold C long (gtecat lib --m32): the parameters read back as written.
#include <stdio.h>
#include <unistd.h>
#include "gts.h"

int main(int argc, char **argv) {
    long offset = argc > 1 ? -500 : 0;
    printf("sizeof_homeprm %u\n", (unsigned)sizeof(THomePrm));
    printf("open %d\n", GT_Open());
    GT_ClrSts(1);
    printf("axison %d\n", GT_AxisOn(1));
    THomePrm prm;
    GT_GetHomePrm(1, &prm);
    prm.mode = 20; prm.moveDir = 1; prm.indexDir = 1; prm.edge = 0;
    prm.velHigh = 50; prm.velLow = 5; prm.acc = 1; prm.dec = 1;  // a search of about 1 s
    prm.searchHomeDistance = 200000; prm.searchIndexDistance = 30000; prm.escapeStep = 1000;
    prm.homeOffset = offset;
    printf("gohome %d\n", GT_GoHome(1, &prm));
    THomeStatus hs;
    for (int i = 0; i < 2000; i++) {
        GT_GetHomeStatus(1, &hs);
        if (!hs.run) break;
        usleep(5000);
    }
    double prf; long sts;
    GT_GetPrfPos(1, &prf, 1, NULL);
    GT_GetSts(1, &sts, 1, NULL);
    printf("run %d\nerror %d\ncapture %ld\ntarget %ld\nprf %.0f\n", hs.run, hs.error,
           hs.capturePos, hs.targetPos, prf);
    THomePrm back;
    GT_GetHomePrm(1, &back);
    printf("back_index %ld\nback_escape %ld\nback_offset %ld\n", back.searchIndexDistance,
           back.escapeStep, back.homeOffset);
    printf("close %d\n", GT_Close());
    return 0;
}
