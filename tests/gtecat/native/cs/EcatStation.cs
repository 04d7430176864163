// New C# code on the generated gts.cs (`gtecat lib --csharp -o gts.cs`): the GTN bring-up of
// the vendor's EtherCAT demo on the manual's figure 5-2 bus (2 drives, 2 IO slaves), the
// configuration loaded by the path it had on the controller's PC, a Trap move, the manual's
// 8-profile read of examples 7-5/7-7/7-8, raw data and EtherCAT IO, an SDO abort code.
// It prints `key value` lines a test reads.
//
//     mcs EcatStation.cs gts.cs && gtecat lib --mono-config -o EcatStation.exe.config
//     GTECAT_ENI=manual_fig5_2.eni mono EcatStation.exe
using System;
using System.Text;
using System.Threading;
using gts;

class EcatStation
{
    const short CORE = 1;

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

    static int Main()
    {
        short rtn = mc.GTN_Open();  // the GTN header's defaults: channel 5, param 1
        Say("open", rtn);
        if (rtn != 0)
        {
            Say("reason", Why());
            return 1;
        }
        Say("init", mc.GTN_InitEcatComm(CORE));
        short ready = 0;
        int polls;
        for (polls = 0; polls < 200; polls++)
        {
            if (mc.GTN_IsEcatReady(CORE, out ready) == 0 && ready == 1)
                break;
            Thread.Sleep(10);
        }
        Say("ready", ready);
        Say("start", mc.GTN_StartEcatComm(CORE));
        Say("reset", mc.GTN_Reset(CORE));
        Say("loadconfig", mc.GTN_LoadConfig(CORE, "\\gugao-board\\gugao1\\test.cfg"));
        Say("clrsts8", mc.GTN_ClrSts(CORE, 1, 8));  // the manual's examples clear 8 axes

        // servo on and a Trap move of axis 1
        Say("axison", mc.GTN_AxisOn(CORE, 1));
        int sts = 0;
        uint clock;
        for (polls = 0; polls < 200 && (sts & 0x200) == 0; polls++)
        {
            mc.GTN_GetSts(CORE, 1, out sts, 1, out clock);
            Thread.Sleep(5);
        }
        Say("enabled", (sts >> 9) & 1);
        mc.TTrapPrm trap;
        Say("prftrap", mc.GTN_PrfTrap(CORE, 1));
        Say("gettrapprm", mc.GTN_GetTrapPrm(CORE, 1, out trap));
        trap.acc = 2;
        trap.dec = 2;
        Say("settrapprm", mc.GTN_SetTrapPrm(CORE, 1, ref trap));
        Say("setpos", mc.GTN_SetPos(CORE, 1, 20000));
        Say("setvel", mc.GTN_SetVel(CORE, 1, 100));
        Say("update", mc.GTN_Update(CORE, 1));
        for (polls = 0; polls < 1000; polls++)
        {
            mc.GTN_GetSts(CORE, 1, out sts, 1, out clock);
            if ((sts & 0x400) == 0)
                break;
            Thread.Sleep(5);
        }
        double[] prfPos = new double[2];
        Say("getprfpos2", mc.GTN_GetPrfPos(CORE, 1, prfPos, 2, out clock));
        Say("prfpos", prfPos[0]);
        int encPos;
        Say("getecatencpos", mc.GTN_GetEcatEncPos(CORE, 1, out encPos));
        Say("ecatencpos", encPos);

        // examples 7-5, 7-7, 7-8: GT_GetPrfVel(1, ADR(arrPrfVel), 8, 0) on this 2-drive bus
        double[] arrPrfVel = new double[8];
        Say("getprfvel8", mc.GTN_GetPrfVel(CORE, 1, arrPrfVel, 8, out clock));
        Say("getprfvel13", mc.GTN_GetPrfVel(CORE, 1, new double[13], 13, out clock));
        int[] sts8 = new int[8];
        Say("getsts8", mc.GTN_GetSts(CORE, 1, sts8, 8, out clock));
        Say("sts8_servo", ((sts8[0] >> 9) & 1) + "" + ((sts8[2] >> 9) & 1) + sts8[7]);

        // raw data and EtherCAT IO (figure 5-2: slave 2's outputs at 32, its inputs at 34)
        byte[] outBytes = { 0xA5, 0x3C };
        byte[] back = new byte[2];
        Say("raw_write", mc.GTN_SetEcatRawData(CORE, 32, 2, outBytes));
        Say("raw_read", mc.GTN_GetEcatRawData(CORE, 32, 2, back));
        Say("raw_back", back[0] | (back[1] << 8));
        Say("raw_write_inputs", mc.GTN_SetEcatRawData(CORE, 34, 2, outBytes));
        Say("io_write", mc.GTN_EcatIOWriteOutput(CORE, 3, 0, 2, new byte[] { 0x0F, 0xF0 }));
        Say("io_read", mc.GTN_EcatIOReadInput(CORE, 3, 0, 2, back));

        // SDO: a good upload, and the abort code of an object that does not exist
        byte[] data = new byte[4];
        uint size, abort;
        Say("sdo_up", mc.GTN_EcatSDOUpload(CORE, 0, 0x6041, 0, data, 4, out size, out abort));
        Say("sdo_size", size);
        Say("sdo_bad", mc.GTN_EcatSDOUpload(CORE, 0, 0x2FFF, 0, data, 4, out size, out abort));
        Say("sdo_bad_abort", abort.ToString("X8"));

        Say("bad_axis", mc.GTN_AxisOn(CORE, 99));
        Say("bad_axis_reason", Why());
        Say("close", mc.GTN_Close());
        Say("done", 1);
        return 0;
    }
}
