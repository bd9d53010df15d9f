/* UART0: the receive interrupt only moves bytes into a ring, the main loop drains it; transmit
 * goes through a ring emptied by the data-register-empty interrupt and never waits. Implements
 * board_tx and the overrun and drop counters. */
#include "uart.h"

#include <avr/interrupt.h>
#include <avr/io.h>
#include <util/atomic.h>

#include "../config.h"
#include "../core/board.h"
#include "protocol_gen.h"

#define RX_MASK (UART_RX_SIZE - 1)
#define TX_MASK (UART_TX_SIZE - 1)

static volatile uint8_t rx_buf[UART_RX_SIZE];
static volatile uint8_t rx_head, rx_tail; /* ISR writes head, main loop writes tail */
static volatile uint8_t tx_buf[UART_TX_SIZE];
static volatile uint8_t tx_head, tx_tail; /* main loop writes head, ISR writes tail */
static volatile uint16_t rx_overruns;      /* written by the receive interrupt only */
static uint16_t tx_dropped;                /* main loop only */

void uart_init(void)
{
    /* 115200 baud from 16 MHz needs double speed: UBRR = 16 gives 117647 (+2.1%). Mode and
     * speed bits are written before UBRR0. */
    UCSR0A = _BV(U2X0);
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00); /* 8N1 */
    UBRR0 = (uint16_t)((F_CPU + 4UL * PROTO_BAUD) / (8UL * PROTO_BAUD) - 1);
    UCSR0B = _BV(RXEN0) | _BV(TXEN0) | _BV(RXCIE0);
}

ISR(USART_RX_vect)
{
    if (UCSR0A & _BV(DOR0)) /* the UART lost a byte before this one: read before UDR0 */
        rx_overruns++;
    uint8_t byte = UDR0;
    uint8_t next = (rx_head + 1) & RX_MASK;
    if (next == rx_tail) { /* a full ring drops the byte; the frame's CRC then fails */
        rx_overruns++;
        return;
    }
    rx_buf[rx_head] = byte;
    rx_head = next;
}

ISR(USART_UDRE_vect)
{
    if (tx_tail == tx_head) {
        UCSR0B &= (uint8_t)~_BV(UDRIE0);
        return;
    }
    UDR0 = tx_buf[tx_tail];
    tx_tail = (tx_tail + 1) & TX_MASK;
}

int16_t uart_read(void)
{
    if (rx_tail == rx_head)
        return -1;
    uint8_t byte = rx_buf[rx_tail];
    rx_tail = (rx_tail + 1) & RX_MASK;
    return byte;
}

uint8_t uart_rx_waiting(void)
{
    return rx_tail != rx_head;
}

void board_tx(const uint8_t *data, uint8_t n)
{
    uint8_t head = tx_head;
    uint8_t room = (uint8_t)((tx_tail - head - 1) & TX_MASK);
    if (room < n) { /* never wait for the line: drop the whole frame and count it */
        tx_dropped++;
        return;
    }
    for (uint8_t i = 0; i < n; i++) {
        tx_buf[head] = data[i];
        head = (head + 1) & TX_MASK;
    }
    tx_head = head;
    UCSR0B |= _BV(UDRIE0);
}

uint16_t board_rx_overruns(void)
{
    uint16_t n;
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { n = rx_overruns; }
    return n;
}

uint16_t board_tx_dropped(void)
{
    return tx_dropped;
}
