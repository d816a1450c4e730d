/* SPDX-License-Identifier: Apache-2.0 */
/* link_emu: a two-port Ethernet link emulator for the network tests (issue 14).
 *
 * Forwards every frame received on interface A out of interface B and back,
 * through AF_PACKET sockets (both interfaces in promiscuous mode), and on the
 * way applies, independently per direction:
 *
 *   --delay MS        one-way delay (default 0)
 *   --jitter MS       each frame's delay drawn uniformly in delay +- jitter
 *                     (clamped at 0)
 *   --no-reorder      with jitter, a frame never leaves before the frame that
 *                     arrived before it (jitter without reordering); default:
 *                     frames may overtake one another
 *   --loss PCT        random loss, independent per frame (in the Good state
 *                     of the Gilbert-Elliott model when --burst is given)
 *   --burst P,R,H     Gilbert-Elliott bursty loss, all in percent: P = chance
 *                     per frame of Good -> Bad, R = chance of Bad -> Good,
 *                     H = loss in Bad (mean burst 100/R frames)
 *   --rate KBIT       bandwidth limit in kbit/s (serialisation of each frame;
 *                     0 = unlimited, the default)
 *   --queue BYTES     backlog allowed before tail drop at --rate (default 256000)
 *   --dup PCT         duplicate a frame (the copy leaves 0.1 ms after it)
 *   --down AT:FOR     the link is cut (every frame dropped both ways) from AT
 *                     to AT+FOR seconds after start; may repeat (up to 8)
 *   --seed N          seed of the random streams (default 1): the same seed
 *                     and the same frames give the same decisions
 *   --duration S      stop by itself after S seconds (required, > 0)
 *   --a IF --b IF     the two interfaces (required)
 *   --ready FILE      written once both sockets are bound (tests wait on it)
 *   --help            a usage summary
 *   --port-stats      also count forwarded IPv4 UDP frames per destination port
 *                     (DDS: one unicast port pair per participant, so per
 *                     process), printed as
 *                       link a->b port=P frames=N bytes=N
 *                     (port 0: IP fragments after the first, without a UDP header)
 *
 * SIGINT / SIGTERM stop it early. On exit it prints one line per direction:
 *   link a->b: in=N out=N dropped=N loss=N queue=N down=N duplicated=N
 *              reordered=N flushed=N bytes_in=N bytes_out=N
 * (reordered = frames sent after a frame that arrived later; flushed = frames
 * still queued at the end). Exit 0, 2 on bad usage, 1 on a socket error.
 *
 * Needs CAP_NET_RAW (root in the link's network namespace). The interfaces
 * should have offloads off (ethtool -K IF tx off tso off gso off gro off):
 * frames are copied as read, so a partial checksum or a 64 kB GSO frame
 * would leave as such. tests/network/sites.sh sets this up. */
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <errno.h>
#include <inttypes.h>
#include <linux/if_packet.h>
#include <net/ethernet.h>
#include <net/if.h>
#include <poll.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#define MAX_FRAME 9216
#define MAX_DOWN 8
#define MAX_QUEUED 65536
#define MAX_PORTS 512

typedef struct opts {
  double delay_ms, jitter_ms, loss, ge_p, ge_r, ge_h, rate_kbit, dup, duration_s;
  double down_at[MAX_DOWN], down_for[MAX_DOWN];
  int ndown, reorder, port_stats;
  long queue_bytes;
  uint64_t seed;
  const char *ifa, *ifb, *ready;
} opts_t;

typedef struct frame {
  int64_t release_ns;
  uint64_t seq; /* arrival order in its direction */
  int len;
  unsigned char *data;
} frame_t;

typedef struct dir {
  const char *name;
  int in_fd, out_fd, out_ifindex;
  uint64_t rng;
  int bad;                                   /* Gilbert-Elliott state */
  int64_t link_free_ns, last_release_ns;     /* serialisation, no-reorder floor */
  uint64_t next_seq, max_sent_seq, sent_any; /* reorder accounting */
  frame_t *heap;
  size_t n;
  uint64_t in, out, drop_loss, drop_queue, drop_down, dups, reordered, bytes_in, bytes_out, tx_err;
  uint16_t port[MAX_PORTS]; /* --port-stats: forwarded frames per UDP destination port */
  uint64_t port_frames[MAX_PORTS], port_bytes[MAX_PORTS];
  int nports;
} dir_t;

/* The UDP destination port of an IPv4 frame (0 for a later fragment), -1 if not UDP over IPv4. */
static int udp_dst_port(const unsigned char *f, int len) {
  if (len < 14 + 20 || f[12] != 0x08 || f[13] != 0x00 || (f[14] >> 4) != 4 || f[23] != 17) return -1;
  int ihl = (f[14] & 15) * 4, frag_off = ((f[20] & 0x1f) << 8) | f[21];
  if (frag_off != 0) return 0;
  if (len < 14 + ihl + 4) return -1;
  return (f[14 + ihl + 2] << 8) | f[14 + ihl + 3];
}

static void count_port(dir_t *d, const unsigned char *f, int len) {
  int p = udp_dst_port(f, len), i;
  if (p < 0) return;
  for (i = 0; i < d->nports && d->port[i] != p; i++) {
  }
  if (i == d->nports) {
    if (d->nports == MAX_PORTS) return;
    d->port[d->nports++] = (uint16_t)p;
  }
  d->port_frames[i]++;
  d->port_bytes[i] += (uint64_t)len;
}

static volatile sig_atomic_t g_stop;
static void on_sig(int s) {
  (void)s;
  g_stop = 1;
}

static int64_t now_ns(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (int64_t)t.tv_sec * 1000000000 + t.tv_nsec;
}

/* splitmix64: small, seedable, the same sequence on every machine. */
static uint64_t rng_next(uint64_t *s) {
  uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}
static double rng_unit(uint64_t *s) { return (double)(rng_next(s) >> 11) * (1.0 / 9007199254740992.0); }

static int heap_less(const frame_t *a, const frame_t *b) {
  return a->release_ns < b->release_ns || (a->release_ns == b->release_ns && a->seq < b->seq);
}
static int heap_push(dir_t *d, frame_t f) {
  if (d->n >= MAX_QUEUED) return -1;
  size_t i = d->n++;
  d->heap[i] = f;
  while (i > 0) {
    size_t p = (i - 1) / 2;
    if (!heap_less(&d->heap[i], &d->heap[p])) break;
    frame_t t = d->heap[i];
    d->heap[i] = d->heap[p];
    d->heap[p] = t;
    i = p;
  }
  return 0;
}
static frame_t heap_pop(dir_t *d) {
  frame_t top = d->heap[0];
  d->heap[0] = d->heap[--d->n];
  size_t i = 0;
  for (;;) {
    size_t l = 2 * i + 1, r = l + 1, m = i;
    if (l < d->n && heap_less(&d->heap[l], &d->heap[m])) m = l;
    if (r < d->n && heap_less(&d->heap[r], &d->heap[m])) m = r;
    if (m == i) break;
    frame_t t = d->heap[i];
    d->heap[i] = d->heap[m];
    d->heap[m] = t;
    i = m;
  }
  return top;
}

static int open_port(const char *ifname, int *ifindex) {
  int fd = socket(AF_PACKET, SOCK_RAW | SOCK_NONBLOCK, htons(ETH_P_ALL));
  if (fd < 0) {
    fprintf(stderr, "link_emu: packet socket: %s (needs CAP_NET_RAW)\n", strerror(errno));
    return -1;
  }
  *ifindex = (int)if_nametoindex(ifname);
  if (*ifindex == 0) {
    fprintf(stderr, "link_emu: interface '%s': %s\n", ifname, strerror(errno));
    close(fd);
    return -1;
  }
  struct sockaddr_ll sll = {.sll_family = AF_PACKET, .sll_protocol = htons(ETH_P_ALL), .sll_ifindex = *ifindex};
  if (bind(fd, (struct sockaddr *)&sll, sizeof sll) < 0) {
    fprintf(stderr, "link_emu: bind to '%s': %s\n", ifname, strerror(errno));
    close(fd);
    return -1;
  }
  struct packet_mreq mr = {.mr_ifindex = *ifindex, .mr_type = PACKET_MR_PROMISC};
  if (setsockopt(fd, SOL_PACKET, PACKET_ADD_MEMBERSHIP, &mr, sizeof mr) < 0)
    fprintf(stderr, "link_emu: '%s' promiscuous: %s (continuing)\n", ifname, strerror(errno));
  int one = 1, buf = 8 << 20;
  /* Our own transmissions must not come back as input. */
  setsockopt(fd, SOL_PACKET, PACKET_IGNORE_OUTGOING, &one, sizeof one);
  setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &buf, sizeof buf);
  setsockopt(fd, SOL_SOCKET, SO_SNDBUFFORCE, &buf, sizeof buf);
  return fd;
}

static int link_down(const opts_t *o, double t_s) {
  for (int i = 0; i < o->ndown; i++)
    if (t_s >= o->down_at[i] && t_s < o->down_at[i] + o->down_for[i]) return 1;
  return 0;
}

/* One frame arrived on d's input at time t: decide its fate, queue it. */
static void admit(dir_t *d, const opts_t *o, const unsigned char *buf, int len, int64_t t, int64_t t0) {
  d->in++;
  d->bytes_in += (uint64_t)len;
  uint64_t seq = d->next_seq++;
  /* Every random draw happens for every frame, in the same order, so one
   * decision never shifts the stream of another. */
  double u_ge = rng_unit(&d->rng), u_loss = rng_unit(&d->rng), u_jit = rng_unit(&d->rng), u_dup = rng_unit(&d->rng);
  if (o->ge_p > 0 || o->ge_r > 0) d->bad = d->bad ? !(u_ge * 100.0 < o->ge_r) : (u_ge * 100.0 < o->ge_p);
  if (link_down(o, (double)(t - t0) * 1e-9)) {
    d->drop_down++;
    return;
  }
  double loss = d->bad ? o->ge_h : o->loss;
  if (loss > 0 && u_loss * 100.0 < loss) {
    d->drop_loss++;
    return;
  }
  int64_t depart = t;
  if (o->rate_kbit > 0) {
    if (d->link_free_ns > t && (double)(d->link_free_ns - t) * o->rate_kbit * 1e-6 / 8.0 > (double)o->queue_bytes) {
      d->drop_queue++;
      return;
    }
    int64_t start = d->link_free_ns > t ? d->link_free_ns : t;
    depart = start + (int64_t)((double)len * 8.0 / (o->rate_kbit * 1e3) * 1e9);
    d->link_free_ns = depart;
  }
  double delay = o->delay_ms + (o->jitter_ms > 0 ? (2.0 * u_jit - 1.0) * o->jitter_ms : 0.0);
  if (delay < 0) delay = 0;
  int64_t rel = depart + (int64_t)(delay * 1e6);
  if (!o->reorder && rel < d->last_release_ns) rel = d->last_release_ns;
  int copies = 1 + (o->dup > 0 && u_dup * 100.0 < o->dup);
  d->last_release_ns = rel + (copies - 1) * 100000; /* a copy too keeps the order */
  for (int c = 0; c < copies; c++) {
    frame_t f = {.release_ns = rel + c * 100000, .seq = seq, .len = len, .data = malloc((size_t)len)};
    if (!f.data || heap_push(d, f) < 0) {
      free(f.data);
      d->drop_queue++;
      return;
    }
    memcpy(f.data, buf, (size_t)len);
    if (c == 1) d->dups++;
  }
}

static void release_due(dir_t *d, int64_t t, int port_stats) {
  while (d->n > 0 && d->heap[0].release_ns <= t) {
    frame_t f = heap_pop(d);
    if (d->sent_any && f.seq < d->max_sent_seq) d->reordered++;
    if (!d->sent_any || f.seq > d->max_sent_seq) d->max_sent_seq = f.seq;
    d->sent_any = 1;
    if (send(d->out_fd, f.data, (size_t)f.len, 0) == f.len) {
      d->out++;
      d->bytes_out += (uint64_t)f.len;
      if (port_stats) count_port(d, f.data, f.len);
    } else {
      d->tx_err++;
    }
    free(f.data);
  }
}

static int parse_num(const char *s, double lo, double hi, double *v, const char *what) {
  char *end;
  errno = 0;
  double x = strtod(s, &end);
  if (errno || end == s || *end || !(x >= lo && x <= hi)) {
    fprintf(stderr, "link_emu: %s: '%s' is not a number in [%g, %g]\n", what, s, lo, hi);
    return -1;
  }
  *v = x;
  return 0;
}

static void usage(FILE *f) {
  fprintf(f, "usage: link_emu --a IF --b IF --duration S [--delay MS] [--jitter MS] [--no-reorder] [--loss PCT]\n"
             "                [--burst P,R,H] [--rate KBIT] [--queue BYTES] [--dup PCT] [--down AT:FOR]...\n"
             "                [--seed N] [--ready FILE] [--port-stats]\n"
             "Forwards Ethernet frames between IF a and IF b with the given impairments, per direction;\n"
             "prints per direction what it did at the end (tests/network/link_emu.c explains each option).\n");
}

static int parse_opts(int argc, char **argv, opts_t *o) {
  *o = (opts_t){.reorder = 1, .queue_bytes = 256000, .seed = 1};
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
    double x;
    if (!strcmp(a, "--help")) {
      usage(stdout);
      exit(0);
    }
    if (!strcmp(a, "--no-reorder")) {
      o->reorder = 0;
      continue;
    }
    if (!strcmp(a, "--port-stats")) {
      o->port_stats = 1;
      continue;
    }
    if (!v) {
      fprintf(stderr, "link_emu: %s: missing value (see the top of link_emu.c)\n", a);
      return -1;
    }
    i++;
    int bad = 0;
    if (!strcmp(a, "--a"))
      o->ifa = v;
    else if (!strcmp(a, "--b"))
      o->ifb = v;
    else if (!strcmp(a, "--ready"))
      o->ready = v;
    else if (!strcmp(a, "--delay"))
      bad = parse_num(v, 0, 10000, &o->delay_ms, a);
    else if (!strcmp(a, "--jitter"))
      bad = parse_num(v, 0, 10000, &o->jitter_ms, a);
    else if (!strcmp(a, "--loss"))
      bad = parse_num(v, 0, 100, &o->loss, a);
    else if (!strcmp(a, "--dup"))
      bad = parse_num(v, 0, 100, &o->dup, a);
    else if (!strcmp(a, "--rate"))
      bad = parse_num(v, 0, 1e8, &o->rate_kbit, a);
    else if (!strcmp(a, "--duration"))
      bad = parse_num(v, 0.001, 86400, &o->duration_s, a);
    else if (!strcmp(a, "--queue")) {
      bad = parse_num(v, 1500, 1e9, &x, a);
      o->queue_bytes = (long)x;
    } else if (!strcmp(a, "--seed")) {
      bad = parse_num(v, 0, 1e15, &x, a);
      o->seed = (uint64_t)x;
    } else if (!strcmp(a, "--burst")) {
      bad = sscanf(v, "%lf,%lf,%lf", &o->ge_p, &o->ge_r, &o->ge_h) != 3 || o->ge_p < 0 || o->ge_p > 100 ||
            o->ge_r < 0 || o->ge_r > 100 || o->ge_h < 0 || o->ge_h > 100;
      if (bad) fprintf(stderr, "link_emu: --burst: '%s' is not P,R,H (percent each)\n", v);
    } else if (!strcmp(a, "--down")) {
      bad = o->ndown >= MAX_DOWN || sscanf(v, "%lf:%lf", &o->down_at[o->ndown], &o->down_for[o->ndown]) != 2 ||
            o->down_at[o->ndown] < 0 || o->down_for[o->ndown] <= 0;
      if (bad) fprintf(stderr, "link_emu: --down: '%s' is not AT:FOR seconds (at most %d)\n", v, MAX_DOWN);
      o->ndown++;
    } else {
      fprintf(stderr, "link_emu: unknown option '%s' (see the top of link_emu.c)\n", a);
      return -1;
    }
    if (bad) return -1;
  }
  if (!o->ifa || !o->ifb || o->duration_s <= 0) {
    fprintf(stderr, "link_emu: --a IF, --b IF and --duration S are required\n");
    usage(stderr);
    return -1;
  }
  return 0;
}

static void report(const dir_t *d) {
  printf("link %s: in=%" PRIu64 " out=%" PRIu64 " dropped=%" PRIu64 " loss=%" PRIu64 " queue=%" PRIu64 " down=%" PRIu64
         " duplicated=%" PRIu64 " reordered=%" PRIu64 " flushed=%zu tx_errors=%" PRIu64 " bytes_in=%" PRIu64
         " bytes_out=%" PRIu64 "\n",
         d->name, d->in, d->out, d->drop_loss + d->drop_queue + d->drop_down, d->drop_loss, d->drop_queue, d->drop_down,
         d->dups, d->reordered, d->n, d->tx_err, d->bytes_in, d->bytes_out);
  for (int i = 0; i < d->nports; i++)
    printf("link %s port=%u frames=%" PRIu64 " bytes=%" PRIu64 "\n", d->name, d->port[i], d->port_frames[i],
           d->port_bytes[i]);
}

/* Forwards until --duration or a signal; 0, or 1 on a socket error. */
static int forward(dir_t d[2], const opts_t *op) {
  const opts_t o = *op;
  int fa = d[0].in_fd, fb = d[1].in_fd;
  int64_t t0 = now_ns(), end = t0 + (int64_t)(o.duration_s * 1e9);
  static unsigned char buf[MAX_FRAME];
  struct pollfd pf[2] = {{.fd = fa, .events = POLLIN}, {.fd = fb, .events = POLLIN}};
  while (!g_stop) {
    int64_t t = now_ns();
    if (t >= end) break;
    release_due(&d[0], t, o.port_stats);
    release_due(&d[1], t, o.port_stats);
    int64_t wake = end;
    for (int k = 0; k < 2; k++)
      if (d[k].n > 0 && d[k].heap[0].release_ns < wake) wake = d[k].heap[0].release_ns;
    int64_t wait = wake - now_ns();
    if (wait < 0) wait = 0;
    struct timespec ts = {.tv_sec = wait / 1000000000, .tv_nsec = wait % 1000000000};
    int r = ppoll(pf, 2, &ts, NULL);
    if (r < 0 && errno != EINTR) {
      perror("link_emu: ppoll");
      return 1;
    }
    for (int k = 0; k < 2 && r > 0; k++) {
      if (!(pf[k].revents & POLLIN)) continue;
      for (int burst = 0; burst < 256; burst++) {
        struct sockaddr_ll from;
        socklen_t fl = sizeof from;
        ssize_t n = recvfrom(pf[k].fd, buf, sizeof buf, MSG_TRUNC, (struct sockaddr *)&from, &fl);
        if (n < 0) break;
        if (from.sll_pkttype == PACKET_OUTGOING) continue;
        if (n > (ssize_t)sizeof buf) { /* a GSO frame: offloads were not turned off */
          d[k].in++;
          d[k].tx_err++;
          continue;
        }
        admit(&d[k], &o, buf, (int)n, now_ns(), t0);
      }
    }
  }
  return 0;
}

int main(int argc, char **argv) {
  opts_t o;
  if (parse_opts(argc, argv, &o) < 0) return 2;
  int ia, ib, fa = open_port(o.ifa, &ia), fb = fa < 0 ? -1 : open_port(o.ifb, &ib);
  if (fa < 0 || fb < 0) return 1;
  dir_t d[2] = {{.name = "a->b", .in_fd = fa, .out_fd = fb, .out_ifindex = ib, .rng = o.seed * 2 + 1},
                {.name = "b->a", .in_fd = fb, .out_fd = fa, .out_ifindex = ia, .rng = o.seed * 2 + 2}};
  for (int k = 0; k < 2; k++) d[k].heap = calloc(MAX_QUEUED, sizeof(frame_t));
  if (!d[0].heap || !d[1].heap) return 1;
  signal(SIGINT, on_sig);
  signal(SIGTERM, on_sig);
  printf("link_emu: %s <-> %s delay=%.1fms jitter=%.1fms reorder=%s loss=%.2f%% burst=%.1f,%.1f,%.1f "
         "rate=%.0fkbit dup=%.2f%% down=%d seed=%" PRIu64 " duration=%.1fs\n",
         o.ifa, o.ifb, o.delay_ms, o.jitter_ms, o.reorder ? "yes" : "no", o.loss, o.ge_p, o.ge_r, o.ge_h, o.rate_kbit,
         o.dup, o.ndown, o.seed, o.duration_s);
  fflush(stdout);
  if (o.ready) {
    FILE *f = fopen(o.ready, "w");
    if (f) fclose(f);
  }
  int rc = forward(d, &o);
  report(&d[0]);
  report(&d[1]);
  for (int k = 0; k < 2; k++) {
    while (d[k].n > 0) free(heap_pop(&d[k]).data);
    free(d[k].heap);
  }
  close(fa);
  close(fb);
  return rc;
}
