// A station program for a 4-axis GTS pulse card, written the way the field's C# programs are:
// its own copy of the vendor wrapper (namespace gts, class mc, [DllImport("gts.dll")] with no
// calling convention, C long as int, out/ref, THomePrm with the three pad3 ints of the C#
// wrappers), a Main that opens the card, loads its configuration by the Windows path it had
// on the machine's PC, jogs, homes straight after the jog (as the vendor's smart-home demo),
// moves point to point and reads IO.  It prints `key value` lines a test reads.
//
//     mcs -r:System.Data -r:System.Drawing -r:System.Windows.Forms CardStation.cs
//     gtecat lib --mono-config -o CardStation.exe.config
//     GTECAT_CARD=gts:4 GTECAT_MACHINE=machine.toml mono CardStation.exe
using System;
using System.Data;             // as the vendor's wrappers ship (nothing here uses them)
using System.Drawing;
using System.Runtime.InteropServices;
using System.Text;
using System.Threading;
using System.Windows.Forms;

namespace gts
{
    public class mc
    {
        public const short MC_LIMIT_POSITIVE = 0;
        public const short MC_LIMIT_NEGATIVE = 1;
        public const short MC_HOME = 3;
        public const short MC_GPO = 12;
        public const short HOME_MODE_HOME = 20;

        public struct TTrapPrm
        {
            public double acc;
            public double dec;
            public double velStart;
            public short smoothTime;
        }

        public struct TJogPrm
        {
            public double acc;
            public double dec;
            public double smooth;
        }

        [StructLayout(LayoutKind.Sequential)]
        public struct THomePrm
        {
            public short mode;
            public short moveDir;
            public short indexDir;
            public short edge;
            public short triggerIndex;
            public short pad1_1;
            public short pad1_2;
            public short pad1_3;
            public double velHigh;
            public double velLow;
            public double acc;
            public double dec;
            public short smoothTime;
            public short pad2_1;
            public short pad2_2;
            public short pad2_3;
            public int homeOffset;
            public int searchHomeDistance;
            public int searchIndexDistance;
            public int escapeStep;
            public int pad3_1;
            public int pad3_2;
            public int pad3_3;
        }

        public struct THomeStatus
        {
            public short run;
            public short stage;
            public short error;
            public short pad1;
            public int capturePos;
            public int targetPos;
        }

        [DllImport("gts.dll")]
        public static extern short GT_Open(short channel, short param);
        [DllImport("gts.dll")]
        public static extern short GT_Close();
        [DllImport("gts.dll")]
        public static extern short GT_Reset();
        [DllImport("gts.dll")]
        public static extern short GT_LoadConfig(string pFile);
        [DllImport("gts.dll")]
        public static extern short GT_ClrSts(short axis, short count);
        [DllImport("gts.dll")]
        public static extern short GT_AxisOn(short axis);
        [DllImport("gts.dll")]
        public static extern short GT_GetSts(short axis, out int pSts, short count, out uint pClock);
        [DllImport("gts.dll")]
        public static extern short GT_GetSts(short axis, int[] pSts, short count, out uint pClock);
        [DllImport("gts.dll")]
        public static extern short GT_PrfTrap(short profile);
        [DllImport("gts.dll")]
        public static extern short GT_SetTrapPrm(short profile, ref TTrapPrm pPrm);
        [DllImport("gts.dll")]
        public static extern short GT_GetTrapPrm(short profile, out TTrapPrm pPrm);
        [DllImport("gts.dll")]
        public static extern short GT_PrfJog(short profile);
        [DllImport("gts.dll")]
        public static extern short GT_SetJogPrm(short profile, ref TJogPrm pPrm);
        [DllImport("gts.dll")]
        public static extern short GT_GetJogPrm(short profile, out TJogPrm pPrm);
        [DllImport("gts.dll")]
        public static extern short GT_SetPos(short profile, int pos);
        [DllImport("gts.dll")]
        public static extern short GT_SetVel(short profile, double vel);
        [DllImport("gts.dll")]
        public static extern short GT_Update(int mask);
        [DllImport("gts.dll")]
        public static extern short GT_Stop(int mask, int option);
        [DllImport("gts.dll")]
        public static extern short GT_GetPrfPos(short profile, out double pValue, short count, out uint pClock);
        [DllImport("gts.dll")]
        public static extern short GT_GetPrfVel(short profile, double[] pValue, short count, out uint pClock);
        [DllImport("gts.dll")]
        public static extern short GT_GetEncPos(short encoder, out double pValue, short count, out uint pClock);
        [DllImport("gts.dll")]
        public static extern short GT_GetClock(out uint pClock, out uint pLoop);
        [DllImport("gts.dll")]
        public static extern short GT_GoHome(short axis, ref THomePrm pHomePrm);
        [DllImport("gts.dll")]
        public static extern short GT_GetHomePrm(short axis, out THomePrm pHomePrm);
        [DllImport("gts.dll")]
        public static extern short GT_GetHomeStatus(short axis, out THomeStatus pHomeStatus);
        [DllImport("gts.dll")]
        public static extern short GT_SetDoBit(short doType, short doIndex, short value);
        [DllImport("gts.dll")]
        public static extern short GT_GetDo(short doType, out int pValue);
        [DllImport("gts.dll")]
        public static extern short GT_GetDi(short diType, out int pValue);
        [DllImport("gts.dll")]
        public static extern short GTE_GetLastError(StringBuilder buf, short size);
    }
}

namespace Station
{
    using gts;

    class Program
    {
        const short HOME_AXIS = 3;

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

        static int Status(short axis)
        {
            int sts;
            uint clk;
            mc.GT_GetSts(axis, out sts, 1, out clk);
            return sts;
        }

        static void WaitStill(short axis, string key)
        {
            int polls = 0;
            while ((Status(axis) & 0x400) != 0 && polls < 2000)
            {
                Thread.Sleep(5);
                polls++;
            }
            Say(key, polls);
        }

        static int Main(string[] args)
        {
            short rtn = mc.GT_Open(0, 1);
            Say("open", rtn);
            if (rtn != 0)
            {
                Say("reason", Why());
                return 1;
            }
            Say("reset", mc.GT_Reset());
            Say("loadconfig", mc.GT_LoadConfig("D:\\cfg\\GTS800.cfg"));
            Say("loadconfig_missing", mc.GT_LoadConfig("D:\\cfg\\missing.cfg"));
            Say("missing_reason", Why());
            Say("clrsts", mc.GT_ClrSts(1, 4));
            for (short axis = 1; axis <= 4; axis++)
                Say("axison" + axis, mc.GT_AxisOn(axis));

            // point to point on axis 1
            mc.TTrapPrm trap;
            Say("prftrap", mc.GT_PrfTrap(1));
            Say("gettrapprm", mc.GT_GetTrapPrm(1, out trap));
            trap.acc = 2;
            trap.dec = 2;
            trap.smoothTime = 0;
            Say("settrapprm", mc.GT_SetTrapPrm(1, ref trap));
            Say("setpos", mc.GT_SetPos(1, 12345));
            Say("setvel", mc.GT_SetVel(1, 100));
            Say("update", mc.GT_Update(1 << 0));
            WaitStill(1, "trap_polls");
            double prfPos, encPos;
            uint clk;
            Say("getprfpos", mc.GT_GetPrfPos(1, out prfPos, 1, out clk));
            Say("prfpos", prfPos);
            Say("getencpos", mc.GT_GetEncPos(1, out encPos, 1, out clk));
            Say("encpos", encPos);
            mc.TTrapPrm back;
            mc.GT_GetTrapPrm(1, out back);
            Say("trap_acc", back.acc);

            // the card's 4 axes at once
            int[] sts = new int[4];
            Say("getsts4", mc.GT_GetSts(1, sts, 4, out clk));
            Say("sts_servo", ((sts[0] >> 9) & 1) + "" + ((sts[1] >> 9) & 1) + ((sts[2] >> 9) & 1) + ((sts[3] >> 9) & 1));
            double[] vel = new double[4];
            Say("getprfvel4", mc.GT_GetPrfVel(1, vel, 4, out clk));
            Say("getsts5", mc.GT_GetSts(1, new int[5], 5, out clk));

            // jog on the home axis, released, and the smart home straight after (the demo)
            mc.TJogPrm jog;
            Say("prfjog", mc.GT_PrfJog(HOME_AXIS));
            Say("getjogprm", mc.GT_GetJogPrm(HOME_AXIS, out jog));
            jog.acc = 1;
            jog.dec = 1;
            jog.smooth = 0;
            Say("setjogprm", mc.GT_SetJogPrm(HOME_AXIS, ref jog));
            Say("jogvel", mc.GT_SetVel(HOME_AXIS, 50));
            Say("jogupdate", mc.GT_Update(1 << (HOME_AXIS - 1)));
            uint t0, t1, loop;
            mc.GT_GetClock(out t0, out loop);
            do
            {
                Thread.Sleep(5);
                mc.GT_GetClock(out t1, out loop);
            } while (t1 - t0 < 100);
            Say("jog_moving", (Status(HOME_AXIS) >> 10) & 1);
            Say("stop", mc.GT_Stop(255, 255));
            Say("home_clrsts", mc.GT_ClrSts(HOME_AXIS, 1));
            mc.THomePrm home;
            Say("gethomeprm", mc.GT_GetHomePrm(HOME_AXIS, out home));
            home.mode = mc.HOME_MODE_HOME;
            home.moveDir = 1;
            home.indexDir = 1;
            home.edge = 0;
            home.velHigh = 100;
            home.velLow = 10;
            home.acc = 2;
            home.dec = 2;
            home.homeOffset = 0;
            home.searchHomeDistance = 0;
            home.escapeStep = 1000;
            home.pad3_3 = 0x5A5A;  // the C# struct is 4 bytes longer than C's
            Say("gohome", mc.GT_GoHome(HOME_AXIS, ref home));
            Say("gohome_reason", Why());
            mc.THomeStatus hs;
            int hpolls = 0;
            do
            {
                Thread.Sleep(10);
                mc.GT_GetHomeStatus(HOME_AXIS, out hs);
                hpolls++;
            } while (hs.run != 0 && hpolls < 3000);
            Say("home_stage", hs.stage);
            Say("home_error", hs.error);
            Say("home_capture", hs.capturePos);
            mc.THomePrm after;
            after.pad3_3 = 77;
            Say("gethomeprm_after", mc.GT_GetHomePrm(HOME_AXIS, out after));
            Say("homeprm_mode", after.mode);
            Say("homeprm_escape", after.escapeStep);
            Say("homeprm_pad3_3", after.pad3_3);

            // IO: a general-purpose output, the home input of the axis standing on it
            int value;
            Say("setdobit", mc.GT_SetDoBit(mc.MC_GPO, 1, 1));
            Say("getdo", mc.GT_GetDo(mc.MC_GPO, out value));
            Say("gpo", value & 0xFFFF);
            Say("getdi", mc.GT_GetDi(mc.MC_HOME, out value));
            Say("di_home", (value >> (HOME_AXIS - 1)) & 1);

            // what the card refuses
            Say("bad_axis", mc.GT_AxisOn(9));
            Say("bad_axis_reason", Why());
            Say("close", mc.GT_Close());
            Say("done", 1);
            return 0;
        }
    }
}
