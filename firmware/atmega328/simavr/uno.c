/* A simulated Arduino Uno: ATmega328P, 16 MHz, the Uno's own bootloader; for avrdude and the host.
 *
 *   uno OPTIBOOT.hex FLASH.bin [--no-autoreset]
 *
 * OPTIBOOT.hex is the bootloader (optiboot_atmega328.hex, loaded at its own address, 0x7E00); the
 * reset vector points there, as the Uno's BOOTRST fuse makes it. OPTIBOOT.hex "-" is a chip with
 * no bootloader (flashed over ISP, BOOTRST unprogrammed): it resets to 0x0000. FLASH.bin holds the application
 * section (0x0000-0x7DFF, erased = 0xFF): read at start if it exists, written back whenever the
 * bootloader has changed it (checked at each reset and on exit), so a flashed board stays flashed.
 *
 * UART0 is bridged to a pseudo-terminal. Opening the port resets the chip with EXTRF set, as the
 * Uno's DTR auto-reset circuit does when a program opens the serial port (a pty has no DTR line,
 * so the open itself is the edge: the bridge is our own, not simavr's uart_pty part, because it
 * must see the port being opened). --no-autoreset is a board whose RESET-EN trace is cut, so a
 * program can open the port and find the chip as it powered up. The simulation follows the wall
 * clock, so optiboot's 1 s wait and the firmware's timeouts are real seconds for avrdude and the
 * host; simavr's sleeping on each empty poll of the UART is off, and so is its own real-time
 * sleep while the AVR sleeps (the throttle does the waiting).
 *
 * stdout, one line each:
 *   pty PATH                    first, once the port exists
 *   reset CYCLE MCUSR           the chip reset (MCUSR as the bootloader sees it, hex)
 *   pwm CYCLE OCR1A OCR1B DIR   a motor output changed (DIR = PD4..PD7 as a 4-bit number)
 *   saved BYTES                 FLASH.bin was written (BYTES programmed, i.e. not 0xFF)
 *   crashed CYCLE PC            simavr stopped the CPU (until the next reset)
 * CYCLE counts CPU cycles since power-on. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/inotify.h>
#include <termios.h>
#include <unistd.h>

#include <simavr/sim_hex.h>

#include "common.h"

#define BAUD 115200UL
#define CYCLES_PER_BYTE (10UL * F_CPU / BAUD) /* the USB-serial adapter's line: 10 bits a byte */
#define BOOT_BASE 0x7E00u                     /* 512-byte boot section: BOOTSZ = 11 on an Uno */

/* ATmega328P data-space addresses (datasheet, register summary) */
#define REG_MCUSR 0x54
#define MCUSR_PORF 0x01
#define MCUSR_EXTRF 0x02
#define REG_PORTD 0x2B
#define REG_OCR1AL 0x88
#define REG_OCR1AH 0x89
#define REG_OCR1BL 0x8A
#define REG_OCR1BH 0x8B
#define DIR_SHIFT 4 /* PD4..PD7: IN1 IN2 IN3 IN4 */

static struct {
    avr_t *avr;
    struct uart0 uart;
    int master, client; /* client: a program has the port open */
    int inotify, opens, autoreset; /* opens: the port's open file descriptions */
    int halted;                    /* simavr stopped the CPU; the next reset restarts it */
    uint8_t queue[4096];     /* bytes from the port waiting for UART0: queue[head..tail) */
    size_t head, tail;
    avr_cycle_count_t next_in, elapsed; /* elapsed: cycles before the last reset */
    const char *flash_path;
    uint8_t saved[BOOT_BASE]; /* the application section as FLASH.bin holds it */
    unsigned last_a, last_b, last_dir;
    volatile sig_atomic_t stop;
} u;

static avr_cycle_count_t now(void)
{
    return u.elapsed + u.avr->cycle;
}

static void on_tx(struct avr_irq_t *irq, uint32_t value, void *param)
{
    (void)irq, (void)param;
    uint8_t byte = (uint8_t)value;
    if (u.client && write(u.master, &byte, 1) < 0) { /* full: lost, as on a wire */ }
}

static int load_application(void)
{
    memset(u.saved, 0xFF, sizeof u.saved);
    FILE *f = fopen(u.flash_path, "rb");
    if (!f)
        return errno == ENOENT ? 0 : -1; /* no file yet: an erased chip */
    size_t n = fread(u.saved, 1, sizeof u.saved, f);
    int bad = ferror(f) || (n != sizeof u.saved && n != 0);
    fclose(f);
    if (bad) {
        fprintf(stderr, "uno: %s is not a %u-byte application image\n", u.flash_path, BOOT_BASE);
        return -1;
    }
    memcpy(u.avr->flash, u.saved, sizeof u.saved);
    return 0;
}

static void save_application(void)
{
    if (!memcmp(u.avr->flash, u.saved, sizeof u.saved))
        return;
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp", u.flash_path);
    FILE *f = fopen(tmp, "wb");
    if (!f || fwrite(u.avr->flash, 1, sizeof u.saved, f) != sizeof u.saved || fclose(f)) {
        perror("uno: saving the flash");
        return;
    }
    if (rename(tmp, u.flash_path) < 0) {
        perror("uno: saving the flash");
        return;
    }
    memcpy(u.saved, u.avr->flash, sizeof u.saved);
    size_t used = 0;
    for (size_t i = 0; i < sizeof u.saved; i++)
        used += u.saved[i] != 0xFF;
    printf("saved %zu\n", used);
}

/* Debian's optiboot_atmega328.hex (built by Debian's avr-gcc) is 532 bytes: it starts at 0x7E00
 * and runs 20 bytes past the end of the 32 KiB flash (its version word at 0x7FFE is written over
 * code). A real ATmega328P could not hold it; here the simulated flash gets that spill (SPILL
 * bytes past 0x7FFF) so that Debian's bootloader runs byte for byte as shipped. */
#define FLASH_END 0x7FFFu
#define SPILL 0x100u

static int load_bootloader(const char *path)
{
    ihex_chunk_p chunks = NULL;
    int count = read_ihex_chunks(path, &chunks);
    if (count <= 0) {
        fprintf(stderr, "uno: cannot read the bootloader %s\n", path);
        return -1;
    }
    uint8_t *flash = realloc(u.avr->flash, FLASH_END + 1 + SPILL);
    if (!flash)
        return -1;
    memset(flash + FLASH_END + 1, 0xFF, SPILL);
    u.avr->flash = flash;
    int bad = 0;
    for (int i = 0; i < count; i++) {
        uint32_t end = chunks[i].baseaddr + chunks[i].size;
        if (chunks[i].baseaddr < BOOT_BASE || end > FLASH_END + 1 + SPILL) {
            bad = 1;
            continue;
        }
        memcpy(flash + chunks[i].baseaddr, chunks[i].data, chunks[i].size);
        if (end - 1 > u.avr->codeend)
            u.avr->codeend = end - 1;
    }
    free_ihex_chunks(chunks);
    if (bad)
        fprintf(stderr, "uno: %s has data outside the boot section (0x7E00-0x7FFF)\n", path);
    return bad ? -1 : 0;
}

static void reset(uint8_t mcusr)
{
    avr_cycle_count_t before = u.avr->cycle;
    u.halted = 0;
    avr_reset(u.avr);
    if (u.avr->cycle < before) /* simavr restarts its cycle count at a reset */
        u.elapsed += before;
    u.avr->data[REG_MCUSR] = mcusr;
    u.uart.xon = 0;
    u.next_in = 0;
    printf("reset %llu %02x\n", (unsigned long long)now(), mcusr);
}

static void feed_uart(void)
{
    if (u.head == u.tail || !u.uart.xon || u.avr->cycle < u.next_in)
        return;
    u.next_in = u.avr->cycle + CYCLES_PER_BYTE;
    avr_raise_irq(u.uart.in, u.queue[u.head++]);
}

static void watch_pins(void)
{
    const uint8_t *d = u.avr->data;
    unsigned a = d[REG_OCR1AL] | d[REG_OCR1AH] << 8, b = d[REG_OCR1BL] | d[REG_OCR1BH] << 8;
    unsigned dir = (d[REG_PORTD] >> DIR_SHIFT) & 0x0F;
    if (a == u.last_a && b == u.last_b && dir == u.last_dir)
        return;
    u.last_a = a, u.last_b = b, u.last_dir = dir;
    printf("pwm %llu %u %u %u\n", (unsigned long long)now(), a, b, dir);
}

static void step(void)
{
    avr_flashaddr_t pc = u.avr->pc;
    avr_cycle_count_t before = u.avr->cycle;
    int state = avr_run(u.avr);
    if (state == cpu_Done || state == cpu_Crashed) {
        /* simavr gives up on code a real chip would run on (a half-written application, say):
         * the chip is dead to the world until a reset, as a hung Uno is */
        printf("crashed %llu %04x\n", (unsigned long long)now(), u.avr->pc);
        u.halted = 1;
        return;
    }
    if (u.avr->cycle < before) /* simavr restarts its cycle count at a reset */
        u.elapsed += before;
    /* at the reset vector, not by running on from erased flash below it: the watchdog reset it */
    if (u.avr->pc == u.avr->reset_pc && pc != u.avr->reset_pc && pc != u.avr->reset_pc - 2) {
        u.uart.xon = 0;
        u.next_in = 0;
        printf("reset %llu %02x\n", (unsigned long long)now(), u.avr->data[REG_MCUSR]);
        save_application(); /* optiboot leaves through a watchdog reset after programming */
    }
    feed_uart();
    watch_pins();
}

/* A program opened the port: DTR goes active, and the auto-reset circuit pulses RESET. */
static void port_opened(void)
{
    tcflush(u.master, TCOFLUSH); /* nothing from before the open reaches the new client */
    u.head = u.tail = 0;
    if (u.autoreset)
        reset(MCUSR_EXTRF);
}

/* Opens and closes of the port, in order, from inotify: a close and a quick reopen between two
 * looks at the port are both seen. */
static void watch_opens(void)
{
    char buf[4096] __attribute__((aligned(__alignof__(struct inotify_event))));
    ssize_t n;
    while ((n = read(u.inotify, buf, sizeof buf)) > 0) {
        for (char *p = buf; p < buf + n; p += sizeof(struct inotify_event)
                                             + ((struct inotify_event *)p)->len) {
            uint32_t mask = ((struct inotify_event *)p)->mask;
            if (mask & IN_OPEN && u.opens++ == 0)
                port_opened();
            if (mask & IN_CLOSE && u.opens > 0)
                u.opens--;
        }
    }
}

/* Notice the port being opened or closed; read what the client wrote. */
static void serve_port(void)
{
    struct pollfd p = {.fd = u.master, .events = POLLIN};
    poll(&p, 1, 0);
    if (u.inotify >= 0) {
        watch_opens();
    } else { /* no inotify: an open is seen if the port stays open until the next look */
        int open_now = !(p.revents & POLLHUP);
        if (open_now && !u.opens)
            port_opened();
        u.opens = open_now;
    }
    u.client = u.opens > 0;
    if (!u.client || !(p.revents & POLLIN))
        return;
    if (u.head == u.tail)
        u.head = u.tail = 0;
    ssize_t n = read(u.master, u.queue + u.tail, sizeof u.queue - u.tail);
    if (n > 0)
        u.tail += (size_t)n;
}

static int open_pty(void)
{
    int master = posix_openpt(O_RDWR | O_NOCTTY);
    if (master < 0 || grantpt(master) < 0 || unlockpt(master) < 0)
        return -1;
    const char *name = ptsname(master);
    int slave = open(name, O_RDWR | O_NOCTTY); /* set raw once; closed so opens can be seen */
    struct termios tio;
    if (slave < 0 || tcgetattr(slave, &tio) < 0)
        return -1;
    cfmakeraw(&tio);
    tcsetattr(slave, TCSANOW, &tio);
    close(slave);
    u.inotify = inotify_init1(IN_NONBLOCK);
    if (u.inotify >= 0 && inotify_add_watch(u.inotify, name, IN_OPEN | IN_CLOSE) < 0) {
        close(u.inotify);
        u.inotify = -1;
    }
    fcntl(master, F_SETFL, O_NONBLOCK);
    printf("pty %s\n", name);
    return master;
}

static int run(void)
{
    double t0 = wall();
    while (!u.stop) {
        /* a tenth of a simulated millisecond, then wait for the wall clock to catch up */
        avr_cycle_count_t end = now() + F_CPU / 10000;
        while (now() < end && !u.halted)
            step();
        if (u.halted) /* time goes on for a stopped chip */
            u.elapsed += end - now();
        serve_port();
        fflush(stdout);
        double ahead = (double)now() / F_CPU - (wall() - t0);
        if (ahead > 0)
            usleep((useconds_t)(ahead * 1e6));
    }
    save_application();
    return 0;
}

static void on_signal(int sig)
{
    (void)sig;
    u.stop = 1;
}

int main(int argc, char **argv)
{
    u.autoreset = !(argc == 4 && !strcmp(argv[3], "--no-autoreset"));
    if (argc != 3 && u.autoreset) {
        fprintf(stderr, "usage: uno OPTIBOOT.hex FLASH.bin [--no-autoreset]\n");
        return 2;
    }
    u.avr = avr_make_mcu_by_name("atmega328p");
    if (!u.avr || avr_init(u.avr) != 0)
        return 1;
    u.avr->frequency = F_CPU;
    u.flash_path = argv[2];
    u.avr->codeend = FLASH_END;
    int bootloader = strcmp(argv[1], "-") != 0;
    if (load_application() < 0 || (bootloader && load_bootloader(argv[1]) < 0))
        return 2;
    u.avr->reset_pc = bootloader ? BOOT_BASE : 0; /* BOOTRST programmed: enter the bootloader */
    u.avr->sleep = no_sleep; /* the wall-clock throttle in run() does the waiting */
    u.last_a = u.last_b = u.last_dir = ~0u;
    uart0_wire(u.avr, &u.uart, on_tx);
    signal(SIGTERM, on_signal);
    signal(SIGINT, on_signal);
    signal(SIGPIPE, SIG_IGN);
    setvbuf(stdout, NULL, _IOLBF, 0);
    u.master = open_pty();
    if (u.master < 0) {
        perror("uno: pty");
        return 1;
    }
    reset(MCUSR_PORF); /* power on */
    return run();
}
