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

/* 1 if s is a TCP port number, 1..65535, in decimal digits and nothing else.
 * getaddrinfo would take more: a service name, and a number past 65535 that
 * it cuts to 16 bits (99999 became 34463), connecting somewhere not asked. */
static int valid_port(const char *s)
{
    long v = 0;
    if (!*s) return 0;
    for (; *s; s++) {
        if (*s < '0' || *s > '9') return 0;
        v = v * 10 + (*s - '0');
        if (v > 65535) return 0; /* also stops before a long string overflows v */
    }
    return v >= 1;
}

static int open_socket(const char *spec, char *err, size_t errlen)
{
    char host[256];
    const char *colon = strrchr(spec, ':');
    if (!colon || colon == spec || (size_t)(colon - spec) >= sizeof host) {
        snprintf(err, errlen, "socket://%s: expected socket://HOST:PORT", spec);
        return -1;
    }
    if (!valid_port(colon + 1)) {
        snprintf(err, errlen, "socket://%s: invalid port '%s' (expected a number in 1..65535)", spec, colon + 1);
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

/* A FIFO is one pipe, not a pair: opened both ways, this end reads back its
 * own bytes (the sender its frames, the board its acks); opened one way, the
 * end that must answer cannot. It is refused before anything goes through it
 * (a receiver can still read one as stdin). Closes fd when open; returns -1. */
static int fifo_refused(const char *port, int fd, char *err, size_t errlen)
{
    snprintf(err, errlen,
             "%s: a FIFO (named pipe) cannot carry the link both ways: use a tty, a pty or socket://HOST:PORT", port);
    if (fd >= 0) close(fd);
    return -1;
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
    struct stat st;
    if (stat(port, &st) == 0 && S_ISFIFO(st.st_mode)) return fifo_refused(port, -1, err, errlen);
    int fd = open(port, O_RDWR | O_NOCTTY);
    if (fd < 0 && (errno == EACCES || errno == EROFS || errno == EISDIR))
        fd = open(port, O_RDONLY);
    else if (fd >= 0)
        *writable = 1;
    if (fd < 0) {
        snprintf(err, errlen, "%s: cannot open: %s", port, strerror(errno));
        return -1;
    }
    if (fstat(fd, &st) == 0) {
        if (S_ISFIFO(st.st_mode)) return fifo_refused(port, fd, err, errlen); /* one made since the stat */
        if (S_ISREG(st.st_mode)) *writable = 0;                               /* a captured stream */
    }
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
