// A wrapper in the vendor's C# style (written for the scan test): declarations, not uses.
using System.Runtime.InteropServices;
namespace gts
{
    public class mc
    {
        public const short MC_AXIS = 30;
        [DllImport("gts.dll")]
        public static extern short GT_Open(short channel, short param);
        [DllImport("gts.dll")]
        public static extern short GT_SetPidNeverCalled(short control, short index);
        [DllImport("gts.dll")]
        public static extern short GT_GetPrfPos(short profile, out double pValue, short count, out uint pClock);
    }
}
