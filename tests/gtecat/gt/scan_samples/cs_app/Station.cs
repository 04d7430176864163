using gts;
class Station
{
    static void Main()
    {
        mc.GT_Open(0, 1);
        double pos; uint clk;
        mc.GT_GetPrfPos(1, out pos, 1, out clk);
        short n = 0;
        int rtn = mc.GTN_GetResCount(1, mc.MC_AXIS, out n);
        if (rtn != mc.CMD_SUCCESS) return;
    }
}
