/* SOES's options for the device of tests/ethercat-firmware (esi/servoone.xml's Sm elements):
   128-byte mailboxes at 0x1000 and 0x1080, outputs at 0x1100 (control 0x64), inputs at 0x1180
   (control 0x20), up to 32 bytes each, 16 mapped entries each (odc's stack: 32 in all). CoE
   and FoE, as the ESI's Mailbox says; no EoE. */
#ifndef __ECAT_OPTIONS_H__
#define __ECAT_OPTIONS_H__
#include "cc.h"
#define USE_FOE          1
#define USE_EOE          0
#define MBXSIZE          128
#define MBXSIZEBOOT      128
#define MBX0_sma         0x1000
#define MBX0_sml         MBXSIZE
#define MBX0_sme         MBX0_sma+MBX0_sml-1
#define MBX0_smc         0x26
#define MBX1_sma         0x1080
#define MBX1_sml         MBXSIZE
#define MBX1_sme         MBX1_sma+MBX1_sml-1
#define MBX1_smc         0x22
#define SM2_sma          0x1100
#define SM2_smc          0x64
#define SM2_act          1
#define SM3_sma          0x1180
#define SM3_smc          0x20
#define SM3_act          1
#define MAX_RXPDO_SIZE   32
#define MAX_TXPDO_SIZE   32
#define MAX_MAPPINGS_SM2 16
#define MAX_MAPPINGS_SM3 16
#endif
