// A program for a 4-axis GTS card written against the older multi-card wrapper: every GT_
// function takes `short cardNum` first (GT_Open(cardNum, channel, param)), C long is int,
// outputs are out/ref, TTrapPrm is passed by ref.  The program's wrapper is its own, as the
// field's are ([DllImport("gts.dll")], no calling convention).  It prints `key value` lines.
//
//     mcs MultiCardStation.cs
//     gtecat lib --abi gts-multicard --mono-config -o MultiCardStation.exe.config
//     GTECAT_CARD=gts:4 mono MultiCardStation.exe
//
// A second card (card 1, an identical controller of its own) is opened after card 0's move:
// its axis stands where card 0's moved, and it keeps working after card 0 is closed.
using System;
using System.Runtime.InteropServices;
using System.Text;
using System.Threading;

namespace gts
{
    public class mc
    {
        public const short MC_GPO = 12;

        public struct TTrapPrm
        {
            public double acc;
            public double dec;
            public double velStart;
            public short smoothTime;
        }

        [DllImport("gts.dll")]
        public static extern short GT_Open(short cardNum, short channel, short param);
        [DllImport("gts.dll")]
        public static extern short GT_Close(short cardNum);
        [DllImport("gts.dll")]
        public static extern short GT_Reset(short cardNum);
        [DllImport("gts.dll")]
        public static extern short GT_LoadConfig(short cardNum, string pFile);
        [DllImport("gts.dll")]
        public static extern short GT_ClrSts(short cardNum, short axis, short count);
        [DllImport("gts.dll")]
        public static extern short GT_AxisOn(short cardNum, short axis);
        [DllImport("gts.dll")]
        public static extern short GT_GetSts(short cardNum, short axis, out int pSts, short count, out uint pClock);
        [DllImport("gts.dll")]
        public static extern short GT_GetSts(short cardNum, short axis, int[] pSts, short count, out uint pClock);
        [DllImport("gts.dll")]
        public static extern short GT_PrfTrap(short cardNum, short profile);
        [DllImport("gts.dll")]
        public static extern short GT_SetTrapPrm(short cardNum, short profile, ref TTrapPrm pPrm);
        [DllImport("gts.dll")]
        public static extern short GT_GetTrapPrm(short cardNum, short profile, out TTrapPrm pPrm);
        [DllImport("gts.dll")]
        public static extern short GT_SetPos(short cardNum, short profile, int pos);
        [DllImport("gts.dll")]
        public static extern short GT_GetPos(short cardNum, short profile, out int pPos);
        [DllImport("gts.dll")]
        public static extern short GT_SetVel(short cardNum, short profile, double vel);
        [DllImport("gts.dll")]
        public static extern short GT_Update(short cardNum, int mask);
        [DllImport("gts.dll")]
        public static extern short GT_GetPrfPos(short cardNum, short profile, out double pValue, short count, out uint pClock);
        [DllImport("gts.dll")]
        public static extern short GT_SetDoBit(short cardNum, short doType, short doIndex, short value);
        [DllImport("gts.dll")]
        public static extern short GT_GetDo(short cardNum, short doType, out int pValue);
        [DllImport("gts.dll")]
        public static extern short GTE_GetLastError(StringBuilder buf, short size);
    }
}

namespace Station
{
    using gts;

    class Program
    {
        const short CARD = 0;

        static void Say(string key, object value)
        {
            Console.WriteLine(key + " " + value);
        }

        static string Why()
        {
            StringBuilder sb = new StringBuilder(512);
            mc.GTE_GetLastError(sb, 512);
            return sb.ToString();
        }

        static int Main(string[] args)
        {
            Say("open_card16", mc.GT_Open(16, 0, 1));
            Say("open_card16_reason", Why());
            short rtn = mc.GT_Open(CARD, 0, 1);
            Say("open", rtn);
            if (rtn != 0)
            {
                Say("reason", Why());
                return 1;
            }
            Say("reset", mc.GT_Reset(CARD));
            Say("loadconfig", mc.GT_LoadConfig(CARD, "GTS800.cfg"));
            Say("clrsts", mc.GT_ClrSts(CARD, 1, 4));
            for (short axis = 1; axis <= 4; axis++)
                Say("axison" + axis, mc.GT_AxisOn(CARD, axis));
            Say("axison_card2", mc.GT_AxisOn(2, 1));
            Say("axison_card2_reason", Why());

            mc.TTrapPrm trap;
            Say("prftrap", mc.GT_PrfTrap(CARD, 1));
            Say("gettrapprm", mc.GT_GetTrapPrm(CARD, 1, out trap));
            trap.acc = 2;
            trap.dec = 2;
            trap.smoothTime = 0;
            Say("settrapprm", mc.GT_SetTrapPrm(CARD, 1, ref trap));
            mc.TTrapPrm back;
            Say("gettrapprm_back", mc.GT_GetTrapPrm(CARD, 1, out back));
            Say("trap_acc", back.acc);
            Say("setpos", mc.GT_SetPos(CARD, 1, 12345));
            int target;
            Say("getpos", mc.GT_GetPos(CARD, 1, out target));
            Say("target", target);
            Say("setvel", mc.GT_SetVel(CARD, 1, 100));
            Say("update", mc.GT_Update(CARD, 1));
            int sts;
            uint clk;
            int polls = 0;
            do
            {
                Thread.Sleep(5);
                mc.GT_GetSts(CARD, 1, out sts, 1, out clk);
            } while ((sts & 0x400) != 0 && ++polls < 2000);
            double prf;
            Say("getprfpos", mc.GT_GetPrfPos(CARD, 1, out prf, 1, out clk));
            Say("prfpos", prf);
            int[] all = new int[4];
            Say("getsts4", mc.GT_GetSts(CARD, 1, all, 4, out clk));
            Say("sts_servo", string.Join("", Array.ConvertAll(all, s => (s & 0x200) != 0 ? "1" : "0")));
            Say("setdobit", mc.GT_SetDoBit(CARD, mc.MC_GPO, 2, 1));
            int gpo;
            Say("getdo", mc.GT_GetDo(CARD, mc.MC_GPO, out gpo));
            Say("gpo", gpo);
            Say("open_card1", mc.GT_Open(1, 0, 1));
            Say("axison_card1", mc.GT_AxisOn(1, 1));
            double prf1;
            Say("getprfpos_card1", mc.GT_GetPrfPos(1, 1, out prf1, 1, out clk));
            Say("prfpos_card1", prf1);
            Say("close", mc.GT_Close(CARD));
            int sts1;
            Say("getsts_card1", mc.GT_GetSts(1, 1, out sts1, 1, out clk));
            Say("servo_card1", (sts1 & 0x200) != 0 ? 1 : 0);
            Say("getsts_closed", mc.GT_GetSts(CARD, 1, out sts1, 1, out clk));
            Say("close_card1", mc.GT_Close(1));
            Say("done", 1);
            return 0;
        }
    }
}
