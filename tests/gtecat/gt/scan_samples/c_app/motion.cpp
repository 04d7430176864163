// A small machine program in the style of the field's C++ applications (written for the
// scan test): bring-up, Trap move, a declared-only call, a misspelt one, constants.
#include "gts.h"

/* GT_NotInComment(1) must not count: it is a comment */
static short bring_up(void)
{
    short rtn = GT_Open(0, 1);
    rtn |= GT_Reset();
    rtn |= GT_LoadConfig("GTS800.cfg");
    rtn |= GT_ClrSts(1, 8);
    return rtn == CMD_SUCCESS ? 0 : 1;
}

int main()
{
    bring_up();
    long sts;
    GT_AxisOn(1);
    GT_PrfTrap(1);
    GT_GetSts(1, &sts);
    const char *s = "GT_InAString(1)";  // nor does a string
    (void)s;
    GT_SetHSIOOpt(1);          // declared only
    GTN_GetResCount(1, MC_AXIS, nullptr);
    GT_MadeUpFunction(3);      // nobody has it
    return MC_NOT_A_CONSTANT;  // a vendor-looking constant nobody defines
}
