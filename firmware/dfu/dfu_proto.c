/* dfu_proto.c - names and one-line meanings of DFU 1.1 states, status codes and
 * requests, for messages on the host and in logs. Freestanding, no libc. */
#include "dfu_proto.h"

static const char *const state_names[] = {
    "appIDLE",        "appDETACH",        "dfuIDLE",     "dfuDNLOAD-SYNC",         "dfuDNBUSY",
    "dfuDNLOAD-IDLE", "dfuMANIFEST-SYNC", "dfuMANIFEST", "dfuMANIFEST-WAIT-RESET", "dfuUPLOAD-IDLE",
    "dfuERROR",
};

static const char *const status_names[] = {
    "OK",      "errTARGET", "errFILE",    "errWRITE",      "errERASE",    "errCHECK_ERASED",
    "errPROG", "errVERIFY", "errADDRESS", "errNOTDONE",    "errFIRMWARE", "errVENDOR",
    "errUSBR", "errPOR",    "errUNKNOWN", "errSTALLEDPKT",
};

static const char *const status_texts[] = {
    "no error",
    "the file is not meant for this device",
    "the file is meant for this device but fails a vendor-specific check",
    "the device could not write its memory",
    "erasing the memory failed",
    "the memory was not blank after erasing",
    "programming the memory failed",
    "the memory read back differs from what was programmed",
    "the data lies outside the device's memory (block out of sequence or image too large)",
    "the device received the end of the download before it expected it",
    "the firmware on the device is corrupt; the device stays in DFU mode",
    "vendor-specific error",
    "the device saw an unexpected USB reset",
    "the device saw an unexpected power-on reset",
    "something went wrong on the device",
    "the device stalled a request it did not expect in its state",
};

static const char *const request_names[] = {
    "DETACH", "DNLOAD", "UPLOAD", "GETSTATUS", "CLRSTATUS", "GETSTATE", "ABORT",
};

const char *dfu_state_name(unsigned state)
{
    return state < sizeof state_names / sizeof state_names[0] ? state_names[state] : "unknown state";
}

const char *dfu_status_name(unsigned status)
{
    return status < sizeof status_names / sizeof status_names[0] ? status_names[status] : "unknown status";
}

const char *dfu_status_text(unsigned status)
{
    return status < sizeof status_texts / sizeof status_texts[0] ? status_texts[status] : "unknown status code";
}

const char *dfu_request_name(unsigned request)
{
    return request < sizeof request_names / sizeof request_names[0] ? request_names[request] : "unknown request";
}
