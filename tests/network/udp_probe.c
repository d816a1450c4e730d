/* SPDX-License-Identifier: Apache-2.0 */
/* udp_probe: numbered UDP datagrams through the emulated link, for the
 * emulator's own test (emulator_test.sh).
 *   udp_probe send ADDR PORT COUNT INTERVAL_US SIZE
 *       sends COUNT datagrams of SIZE bytes (>= 8), each starting with its
 *       number 0..COUNT-1 (decimal text), INTERVAL_US apart;
 *   udp_probe recv PORT QUIET_MS
 *       prints the number of every datagram received, one per line, in
 *       arrival order, until none came for QUIET_MS (or 120 s in all).
 * Exit 0, 2 on bad usage, 1 on a socket error. */
#define _POSIX_C_SOURCE 200809L
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

static int do_send(const char *addr, int port, long count, long interval_us, int size) {
  int fd = socket(AF_INET, SOCK_DGRAM, 0);
  struct sockaddr_in to = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
  if (fd < 0 || inet_pton(AF_INET, addr, &to.sin_addr) != 1) {
    perror("udp_probe: send");
    return 1;
  }
  char buf[9000];
  memset(buf, ' ', sizeof buf);
  struct timespec next;
  clock_gettime(CLOCK_MONOTONIC, &next);
  for (long i = 0; i < count; i++) {
    int n = snprintf(buf, sizeof buf, "%ld", i);
    buf[n] = ' ';
    if (sendto(fd, buf, (size_t)size, 0, (struct sockaddr *)&to, sizeof to) != size) perror("udp_probe: sendto");
    next.tv_nsec += interval_us * 1000;
    while (next.tv_nsec >= 1000000000) next.tv_nsec -= 1000000000, next.tv_sec++;
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, NULL);
  }
  close(fd);
  return 0;
}

static int do_recv(int port, int quiet_ms) {
  int fd = socket(AF_INET, SOCK_DGRAM, 0), buf_sz = 4 << 20;
  struct sockaddr_in me = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port), .sin_addr.s_addr = INADDR_ANY};
  setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &buf_sz, sizeof buf_sz);
  if (fd < 0 || bind(fd, (struct sockaddr *)&me, sizeof me) < 0) {
    perror("udp_probe: recv");
    return 1;
  }
  fprintf(stderr, "udp_probe: listening on %d\n", port);
  char buf[9001];
  struct pollfd pf = {.fd = fd, .events = POLLIN};
  for (int waited = 0, got_any = 0; waited < 120000;) {
    int r = poll(&pf, 1, got_any ? quiet_ms : 1000);
    if (r <= 0) {
      if (got_any) break;
      waited += 1000;
      continue;
    }
    ssize_t n = recv(fd, buf, sizeof buf - 1, 0);
    if (n <= 0) continue;
    buf[n] = 0;
    got_any = 1;
    printf("%ld\n", strtol(buf, NULL, 10));
  }
  close(fd);
  return 0;
}

int main(int argc, char **argv) {
  if (argc == 7 && !strcmp(argv[1], "send") && atoi(argv[6]) >= 8 && atoi(argv[6]) <= 9000)
    return do_send(argv[2], atoi(argv[3]), atol(argv[4]), atol(argv[5]), atoi(argv[6]));
  if (argc == 4 && !strcmp(argv[1], "recv")) return do_recv(atoi(argv[2]), atoi(argv[3]));
  fprintf(stderr, "usage: udp_probe send ADDR PORT COUNT INTERVAL_US SIZE | udp_probe recv PORT QUIET_MS\n");
  return 2;
}
