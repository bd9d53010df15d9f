/* Runs the real firmware ELF in simavr (ATmega328P, 16 MHz) and shows what its pins do.
 *
 *   harness FIRMWARE.elf           scripted, as fast as it can: commands on stdin
 *   harness FIRMWARE.elf --pty     real time, UART0 bridged to a pseudo-terminal
 *
 * Scripted commands, one a line:
 *   send HEX     queue bytes for UART0, one every byte time at PROTO_BAUD
 *   flow 1|0     1 (default): a byte goes in only while the UART says XON (never overruns);
 *                0: at line rate whatever the UART says, as a host without flow control does,
 *                so the receiver overruns when the firmware falls behind
 *   run MS       simulate MS milliseconds
 *   quiet 0|1    stop or start printing each "in" byte (counts are kept either way)
 *   fill SEED    fill SRAM (0x100-0x8FF) with a pseudo-random pattern from SEED, as a real
 *                chip powers up with RAM undefined (simavr starts it zeroed); before any run
 *   poke ADDR HEX write bytes into the data space at ADDR (hex), e.g. a .noinit record or MCUSR
 *   stack SEED ADDR  print "stack LOWEST": the lowest address from ADDR (hex) up whose byte
 *                no longer holds the pattern of fill SEED: the stack's deepest point so far
 *   reset FLAGS  reset the chip now, RAM kept (as on a real chip), MCUSR = FLAGS (hex): 0 is
 *                what the application sees behind optiboot 4.4
 *   ticks 0|1    stop or start printing each Timer0 compare interrupt the CPU takes (the 1 kHz tick)
 *   sweep N      the rest of the script, N times from this same state (a fork each): trial K
 *                raises Timer0's compare interrupt once more after K instructions have run
 *                (awake, ISRs included), so an interrupt lands at every instruction boundary of
 *                what follows in turn, as the chip takes it (not before interrupts are on again);
 *                the extra tick is a tick like any other (the firmware's ms clock gains one)
 * Events on stdout, times in CPU cycles since power-on:
 *   in CYCLE BYTE              a byte entered UART0 (its start bit)
 *   tx CYCLE BYTE              UART0 sent a byte
 *   io CYCLE PORTB DDRB PORTD DDRD TCCR1A TCCR1B ICR1 OCR1A OCR1B MCUSR WDTCSR
 *                              one of these registers changed (hex); the pins are derived from
 *                              them (host/emulator/pins.py): simavr 1.6 does not report the
 *                              Timer1 PWM toggles on PB1/PB2 (docs: shared simavr notes)
 *   reset CYCLE                the chip reset (the watchdog, in these tests)
 *   tick CYCLE                 the CPU took the Timer0 compare interrupt (with ticks 1)
 *   force CYCLE                a sweep's trial raised its extra tick (taken when the CPU can)
 *   trial K                    a sweep's trial K begins; the events that follow, up to its
 *                              end line, are its own, after those printed before the sweep
 *   watchdog CYCLE ...         the datasheet's watchdog reset that simavr does not make (below)
 *   end CYCLE INS IN TX RESETS SECONDS   at the end of input
 * In --pty mode stdout has the one line "pty PATH"; the io and reset events go to stderr. */
#define _GNU_SOURCE
#include <fcntl.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <sys/wait.h>
#include <unistd.h>

#include <simavr/sim_elf.h>

#include "common.h"
#include "protocol_gen.h"

#define CYCLES_PER_BYTE (10UL * F_CPU / PROTO_BAUD) /* the host's line: 10 bits a byte */
#define TIMER0_COMPA_VECTOR 14                        /* ATmega328P interrupt vector number */

/* ATmega328P data-space addresses of the watched registers (datasheet, register summary); a
 * 16-bit register is listed by its low byte and printed whole */
static const struct {
    uint16_t addr;
    uint8_t wide;
} watched[] = {
    {0x25, 0}, /* PORTB */
    {0x24, 0}, /* DDRB */
    {0x2B, 0}, /* PORTD */
    {0x2A, 0}, /* DDRD */
    {0x80, 0}, /* TCCR1A */
    {0x81, 0}, /* TCCR1B */
    {0x86, 1}, /* ICR1 */
    {0x88, 1}, /* OCR1A */
    {0x8A, 1}, /* OCR1B */
    {0x54, 0}, /* MCUSR */
    {0x60, 0}, /* WDTCSR */
};
#define N_WATCHED (sizeof watched / sizeof watched[0])

static struct {
    avr_t *avr;
    struct uart0 uart;
    int flow, feeding;
    uint8_t *queue; /* bytes waiting for UART0: queue[q_head..q_tail) */
    size_t q_head, q_tail, q_cap;
    avr_cycle_count_t next_in;
    int quiet, pty_fd;
    FILE *events; /* io and reset lines */
    unsigned long n_in, n_tx, resets;
    unsigned last[N_WATCHED];
    avr_int_vector_t *tick;        /* Timer0 compare A */
    int ticks;                     /* print each tick taken */
    unsigned long awake, force_at; /* a sweep's trial: instructions run, when to force a tick */
    int forcing;
} h;

static void on_tx(struct avr_irq_t *irq, uint32_t value, void *param)
{
    (void)irq, (void)param;
    uint8_t byte = (uint8_t)value;
    h.n_tx++;
    if (h.pty_fd >= 0) {
        if (write(h.pty_fd, &byte, 1) < 0) { /* no reader yet: the byte is lost, as on a wire */ }
    } else {
        printf("tx %llu %02x\n", (unsigned long long)h.avr->cycle, byte);
    }
}

/* Cycle timer: one byte into UART0 per byte time while the queue has bytes. A timer, not a
 * check between instructions, so a byte arrives on time also while the CPU sleeps. */
static avr_cycle_count_t inject(struct avr_t *avr, avr_cycle_count_t when, void *param)
{
    (void)param;
    if (h.q_head == h.q_tail) {
        h.feeding = 0;
        return 0;
    }
    if (h.flow && !h.uart.xon)
        return when + CYCLES_PER_BYTE / 16; /* the UART is full: look again shortly */
    uint8_t byte = h.queue[h.q_head++];
    h.n_in++;
    if (h.pty_fd < 0 && !h.quiet)
        printf("in %llu %02x\n", (unsigned long long)avr->cycle, byte);
    avr_raise_irq(h.uart.in, byte);
    h.next_in = when + CYCLES_PER_BYTE;
    return h.next_in;
}

static void start_feeding(void)
{
    if (h.feeding || h.q_head == h.q_tail)
        return;
    h.feeding = 1;
    avr_cycle_count_t now = h.avr->cycle;
    avr_cycle_timer_register(h.avr, h.next_in > now ? h.next_in - now : 1, inject, NULL);
}

static void watch_io(void)
{
    const uint8_t *d = h.avr->data;
    int changed = 0;
    for (size_t i = 0; i < N_WATCHED; i++) {
        uint16_t a = watched[i].addr;
        unsigned v = d[a] | (watched[i].wide ? d[a + 1] << 8 : 0);
        changed |= v != h.last[i];
        h.last[i] = v;
    }
    if (!changed)
        return;
    fprintf(h.events, "io %llu", (unsigned long long)h.avr->cycle);
    for (size_t i = 0; i < N_WATCHED; i++)
        fprintf(h.events, " %x", h.last[i]);
    fputc('\n', h.events);
}

/* The watchdog in interrupt-and-reset mode with its interrupt not taken (interrupts held off):
 * simavr 1.6 raises the interrupt again at every timeout and never resets; the ATmega328P
 * datasheet (10.9.2: the first time-out sets WDIF, executing the vector clears WDIE and goes to
 * system reset mode) leaves WDIE set, and this harness takes the worse reading that matches
 * the chip's stated purpose, a reset at the next time-out: WDIF still pending one whole
 * watchdog period after it was raised resets the chip (MCUSR WDRF), RAM kept. */
static void reset_now(unsigned flags);

static void datasheet_watchdog(void)
{
    static avr_cycle_count_t pending_since;
    uint8_t w = h.avr->data[0x60];
    if (!(w & 0x80) || !(w & 0x08)) { /* WDIF not pending, or WDE off */
        pending_since = 0;
        return;
    }
    if (!pending_since) {
        pending_since = h.avr->cycle;
        return;
    }
    unsigned wdp = (w & 7) | (w >> 2 & 8);
    avr_cycle_count_t period = F_CPU / 1000 * (16u << wdp);
    if (h.avr->cycle - pending_since >= period) {
        pending_since = 0;
        fprintf(h.events, "watchdog %llu interrupt not taken: reset\n",
                (unsigned long long)h.avr->cycle);
        reset_now(0x08);
    }
}

static int step(void)
{
    avr_flashaddr_t pc = h.avr->pc;
    if (h.forcing && h.avr->state == cpu_Running && h.awake++ == h.force_at) {
        h.forcing = 0;
        fprintf(h.events, "force %llu %x\n", (unsigned long long)h.avr->cycle, h.avr->pc);
        avr_raise_interrupt(h.avr, h.tick);
    }
    int state = avr_run(h.avr);
    if (h.ticks && h.avr->pc == TIMER0_COMPA_VECTOR * 4 && pc != h.avr->pc)
        fprintf(h.events, "tick %llu\n", (unsigned long long)h.avr->cycle);
    if (state == cpu_Done || state == cpu_Crashed) {
        printf("crashed %llu state %d\n", (unsigned long long)h.avr->cycle, state);
        return -1;
    }
    if (h.avr->pc == 0 && pc != 0) {
        h.resets++;
        h.uart.xon = 0; /* hold bytes until the reset firmware enables its UART again */
        h.feeding = 0; /* the reset dropped the cycle timers */
        start_feeding();
        fprintf(h.events, "reset %llu\n", (unsigned long long)h.avr->cycle);
    }
    watch_io();
    datasheet_watchdog();
    return 0;
}

static avr_cycle_count_t wake(struct avr_t *avr, avr_cycle_count_t when, void *param)
{
    (void)avr, (void)when, (void)param;
    return 0; /* nothing to do: the timer only ends a sleep at the end of a run */
}

static int run_until(avr_cycle_count_t end)
{
    if (end > h.avr->cycle) /* a sleeping CPU would otherwise run on to its next interrupt */
        avr_cycle_timer_register(h.avr, end - h.avr->cycle, wake, NULL);
    while (h.avr->cycle < end)
        if (step() < 0)
            return -1;
    return 0;
}

static void queue_byte(uint8_t byte)
{
    if (h.q_head == h.q_tail)
        h.q_head = h.q_tail = 0;
    if (h.q_tail == h.q_cap) {
        h.q_cap = h.q_cap ? 2 * h.q_cap : 4096;
        h.queue = realloc(h.queue, h.q_cap);
        if (!h.queue) {
            perror("harness");
            exit(1);
        }
    }
    h.queue[h.q_tail++] = byte;
    start_feeding();
}

static void queue_hex(const char *hex)
{
    for (; hex[0] && hex[1]; hex += 2) {
        unsigned v;
        if (sscanf(hex, "%2x", &v) != 1)
            break;
        queue_byte((uint8_t)v);
    }
}

static void fill(unsigned seed)
{
    uint32_t x = seed * 2654435761u + 1;
    for (unsigned a = 0x100; a <= 0x8FF; a++) {
        x ^= x << 13, x ^= x >> 17, x ^= x << 5;
        h.avr->data[a] = (uint8_t)(x >> 24);
    }
}

/* The lowest address from `from` up that no longer holds the fill pattern: with RAM filled at
 * power-on, the deepest the stack has reached (a write of the very byte the pattern had there
 * goes unseen, so this may miss a byte or so). Prints "stack LOWEST". */
static void stack_mark(unsigned seed, unsigned from)
{
    uint32_t x = seed * 2654435761u + 1;
    unsigned lowest = 0x900;
    for (unsigned a = 0x100; a <= 0x8FF; a++) {
        x ^= x << 13, x ^= x >> 17, x ^= x << 5;
        if (a >= from && lowest == 0x900 && h.avr->data[a] != (uint8_t)(x >> 24))
            lowest = a;
    }
    printf("stack %x\n", lowest);
}

static void poke(const char *args)
{
    unsigned addr, v;
    int n;
    if (sscanf(args, "%x %n", &addr, &n) != 1)
        return;
    for (args += n; args[0] && args[1] && sscanf(args, "%2x", &v) == 1 && addr <= 0x8FF; args += 2)
        h.avr->data[addr++] = (uint8_t)v;
}

static void reset_now(unsigned flags)
{
    uint8_t ram[0x800];
    memcpy(ram, h.avr->data + 0x100, sizeof ram);
    avr_cycle_count_t cycle = h.avr->cycle;
    avr_reset(h.avr);
    if (h.avr->cycle < cycle) /* keep one time line across the reset */
        h.avr->cycle = cycle;
    memcpy(h.avr->data + 0x100, ram, sizeof ram);
    h.avr->data[0x54] = (uint8_t)flags;
    h.resets++;
    h.uart.xon = 0;
    h.feeding = 0;
    start_feeding();
    fprintf(h.events, "reset %llu\n", (unsigned long long)h.avr->cycle);
}

static int command(const char *line);

/* sweep N: run the lines that follow N times, each in a child process that starts from this
 * state; the children run one after another, so their output does not interleave. */
static int sweep(unsigned long n, char **rest, size_t n_rest)
{
    for (unsigned long k = 0; k < n; k++) {
        fflush(stdout);
        pid_t pid = fork();
        if (pid < 0) {
            perror("harness: fork");
            return 1;
        }
        if (pid == 0) {
            h.forcing = 1, h.awake = 0, h.force_at = k;
            printf("trial %lu\n", k);
            for (size_t i = 0; i < n_rest; i++)
                if (command(rest[i]))
                    _exit(1);
            printf("end %llu %llu %lu %lu %lu 0\n", (unsigned long long)h.avr->cycle,
                   (unsigned long long)h.avr->cycle, h.n_in, h.n_tx, h.resets);
            fflush(stdout);
            _exit(0);
        }
        int status;
        if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status))
            return 1;
    }
    return 0;
}

/* One scripted command; non-zero ends the script (1: the firmware crashed, 2: bad input). */
static int command(const char *line)
{
    char cmd[16];
    double arg = 0;
    unsigned flags, seed;
    if (sscanf(line, "%15s", cmd) != 1)
        return 0;
    if (!strcmp(cmd, "send"))
        queue_hex(line + 5);
    else if (!strcmp(cmd, "quiet") && sscanf(line + 6, "%lf", &arg) == 1)
        h.quiet = arg != 0;
    else if (!strcmp(cmd, "flow") && sscanf(line + 5, "%lf", &arg) == 1)
        h.flow = arg != 0;
    else if (!strcmp(cmd, "ticks") && sscanf(line + 6, "%lf", &arg) == 1)
        h.ticks = arg != 0;
    else if (!strcmp(cmd, "fill") && sscanf(line + 5, "%lf", &arg) == 1)
        fill((unsigned)arg);
    else if (!strcmp(cmd, "stack") && sscanf(line + 6, "%u %x", &seed, &flags) == 2)
        stack_mark(seed, flags);
    else if (!strcmp(cmd, "poke"))
        poke(line + 5);
    else if (!strcmp(cmd, "reset") && sscanf(line + 6, "%x", &flags) == 1)
        reset_now(flags);
    else if (!strcmp(cmd, "run") && sscanf(line + 4, "%lf", &arg) == 1) {
        if (run_until(h.avr->cycle + (avr_cycle_count_t)(arg * F_CPU / 1000)) < 0)
            return 1;
    } else {
        fprintf(stderr, "harness: unknown command: %.40s\n", line);
        return 2;
    }
    fflush(stdout);
    return 0;
}

static int scripted(void)
{
    char *line = NULL;
    size_t cap = 0;
    double t0 = wall();
    watch_io(); /* the registers at power-on */
    while (getline(&line, &cap, stdin) > 0) {
        unsigned long n;
        if (sscanf(line, "sweep %lu", &n) == 1) {
            char **rest = NULL;
            size_t n_rest = 0;
            while (getline(&line, &cap, stdin) > 0) {
                rest = realloc(rest, ++n_rest * sizeof *rest);
                if (!rest || !(rest[n_rest - 1] = strdup(line)))
                    return 1;
            }
            return sweep(n, rest, n_rest);
        }
        int r = command(line);
        if (r)
            return r;
    }
    free(line);
    printf("end %llu %llu %lu %lu %lu %.3f\n", (unsigned long long)h.avr->cycle,
           (unsigned long long)h.avr->cycle, h.n_in, h.n_tx, h.resets, wall() - t0);
    return 0;
}

static int open_pty(void)
{
    int master = posix_openpt(O_RDWR | O_NOCTTY);
    if (master < 0 || grantpt(master) < 0 || unlockpt(master) < 0)
        return -1;
    const char *name = ptsname(master);
    int slave = open(name, O_RDWR | O_NOCTTY); /* held open: clients may come and go */
    struct termios tio;
    tcgetattr(slave, &tio);
    cfmakeraw(&tio);
    tcsetattr(slave, TCSANOW, &tio);
    fcntl(master, F_SETFL, O_NONBLOCK);
    printf("pty %s\n", name);
    fflush(stdout);
    return master;
}

static int real_time(void)
{
    h.pty_fd = open_pty();
    if (h.pty_fd < 0) {
        perror("harness: pty");
        return 1;
    }
    double t0 = wall();
    for (;;) {
        /* one simulated millisecond, then wait for the wall clock to catch up */
        if (run_until(h.avr->cycle + F_CPU / 1000) < 0)
            return 1;
        uint8_t buf[256];
        ssize_t n;
        while ((n = read(h.pty_fd, buf, sizeof buf)) > 0)
            for (ssize_t i = 0; i < n; i++)
                queue_byte(buf[i]);
        fflush(stdout);
        double ahead = (double)h.avr->cycle / F_CPU - (wall() - t0);
        if (ahead > 0)
            usleep((useconds_t)(ahead * 1e6));
    }
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: harness FIRMWARE.elf [--pty]\n");
        return 2;
    }
    elf_firmware_t fw;
    memset(&fw, 0, sizeof fw);
    if (elf_read_firmware(argv[1], &fw) != 0) {
        fprintf(stderr, "harness: cannot read %s\n", argv[1]);
        return 2;
    }
    h.avr = avr_make_mcu_by_name("atmega328p");
    avr_init(h.avr);
    avr_load_firmware(h.avr, &fw);
    h.avr->frequency = F_CPU;
    h.pty_fd = -1;
    h.flow = 1;
    for (size_t i = 0; i < N_WATCHED; i++)
        h.last[i] = ~0u; /* the first step prints the registers at power-on */
    for (int i = 0; i < h.avr->interrupts.vector_count; i++)
        if (h.avr->interrupts.vector[i]->vector == TIMER0_COMPA_VECTOR)
            h.tick = h.avr->interrupts.vector[i];
    if (!h.tick) {
        fprintf(stderr, "harness: no Timer0 compare vector\n");
        return 2;
    }
    uart0_wire(h.avr, &h.uart, on_tx);
    int pty = argc > 2 && !strcmp(argv[2], "--pty");
    h.events = pty ? stderr : stdout;
    if (!pty)
        h.avr->sleep = no_sleep; /* scripted mode runs as fast as it can */
    setvbuf(stdout, NULL, _IOFBF, 1 << 16);
    return pty ? real_time() : scripted();
}
