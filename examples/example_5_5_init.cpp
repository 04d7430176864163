/* Manual example 5-5, "EtherCAT initialisation in C or C++", as the manual writes it.
 *
 *     g++ example_5_5_init.cpp $(python3 -m gtecat lib --cflags --libs) -o example_5_5_init
 *     GTECAT_ENI=manual_fig5_2.eni ./example_5_5_init
 *
 * Run it in a folder holding GTS800.cfg (`gtecat example example_5_5` writes one): the
 * manual loads "\hard disk\CPAC\GTS800.cfg", the file's place on the controller's own disk;
 * a path that does not exist here is found by its name in the working folder (the master log
 * says so).  Two things the listing leaves out are added: the declaration of `status`, and a
 * line printed at its TODO.  GT_Open(CHANNEL_PCI_ECATCH) has one argument: the second, param,
 * takes the header's C++ default - so this is C++ (a C compiler wants both).
 */
#include <stdio.h>
#include "gts.h"
int main(int argc, char *argv[])
{
    short rtn;
    short status = 0; /* added: the listing uses it undeclared */
    rtn = GT_Open(CHANNEL_PCI_ECATCH);
    if(rtn){
        printf("Not find ecat device\n");
        return -1;
    }
    rtn = GT_InitEcatComm();
    if(rtn){
        printf("EtherCAT communication error\n");
        return -1;
    }
    /*wait untill EtherCAT comminication OK*/
    do {
        rtn = GT_IsEcatReady(&status);
    }
    while(status != 1 || rtn != 0);

    rtn = GT_StartEcatComm();
    rtn = GT_Reset();
    rtn = GT_LoadConfig("\\hard disk\\CPAC\\GTS800.cfg");
    //TODO: add other GT command below
    printf("EtherCAT ready, GT_LoadConfig returned %d\n", rtn); /* added */
    return 0;
}
