/* UART0 at PROTO_BAUD with interrupt-driven receive and transmit rings. */
#ifndef UART_H
#define UART_H

#include <stdint.h>

void uart_init(void);
/* Next received byte, or -1 when none is waiting. */
int16_t uart_read(void);
uint8_t uart_rx_waiting(void);

#endif
