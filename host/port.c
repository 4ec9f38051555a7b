/* port.c - open a frame-link port (see port.h): a tty or pty set raw, a TCP
 * socket as a client, stdin, or a captured stream file. */
#include "port.h"

#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

static int open_socket(const char *spec, char *err, size_t errlen)
{
    char host[256];
    const char *colon = strrchr(spec, ':');
    if (!colon || colon == spec || (size_t)(colon - spec) >= sizeof host) {
        snprintf(err, errlen, "socket://%s: expected socket://HOST:PORT", spec);
        return -1;
    }
    memcpy(host, spec, (size_t)(colon - spec));
    host[colon - spec] = '\0';
    struct addrinfo hints = {0}, *res = NULL;
    hints.ai_socktype = SOCK_STREAM;
    int rc = getaddrinfo(host, colon + 1, &hints, &res);
    if (rc != 0) {
        snprintf(err, errlen, "socket://%s: %s", spec, gai_strerror(rc));
        return -1;
    }
    int fd = -1;
    for (struct addrinfo *a = res; a && fd < 0; a = a->ai_next) {
        fd = socket(a->ai_family, a->ai_socktype, a->ai_protocol);
        if (fd >= 0 && connect(fd, a->ai_addr, a->ai_addrlen) != 0) {
            snprintf(err, errlen, "socket://%s: cannot connect: %s", spec, strerror(errno));
            close(fd);
            fd = -1;
        }
    }
    freeaddrinfo(res);
    return fd;
}

static speed_t baud_code(long baud)
{
    switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 921600: return B921600;
    default: return 0;
    }
}

int port_open(const char *port, long baud, int *writable, char *err, size_t errlen)
{
    *writable = 0;
    if (!strcmp(port, "-")) return 0;
    if (!strncmp(port, "socket://", 9)) {
        int fd = open_socket(port + 9, err, errlen);
        *writable = fd >= 0;
        return fd;
    }
    int fd = open(port, O_RDWR | O_NOCTTY);
    if (fd < 0 && (errno == EACCES || errno == EROFS || errno == EISDIR))
        fd = open(port, O_RDONLY);
    else if (fd >= 0)
        *writable = 1;
    if (fd < 0) {
        snprintf(err, errlen, "%s: cannot open: %s", port, strerror(errno));
        return -1;
    }
    struct stat st;
    if (fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) *writable = 0; /* a captured stream */
    if (isatty(fd)) {
        struct termios t;
        speed_t sp = baud_code(baud);
        if (!sp) {
            snprintf(err, errlen, "%s: unsupported speed %ld", port, baud);
            close(fd);
            return -1;
        }
        if (tcgetattr(fd, &t) == 0) {
            cfmakeraw(&t);
            cfsetispeed(&t, sp);
            cfsetospeed(&t, sp);
            tcsetattr(fd, TCSANOW, &t);
        }
    }
    return fd;
}
