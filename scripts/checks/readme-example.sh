#!/usr/bin/env bash
# The C examples of the README and of two headers must stay true: the
# README's first ```c block is compiled against the core with the project's
# warning set and run; the TYPED USE example of tase/host.h (its #include
# lines first, the rest in a function) and the WIRING IT UP example of
# tase/bm_dma.h (file scope, after stand-ins for the STM32 HAL names) are
# compiled with the same warnings, taken from the headers word for word.
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
out=${1:-$TASE_ROOT/build/readme-example}
mkdir -p "$out"
warn=(-std=c99 -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow -Werror)
awk '/^```c/{n++; if (n == 1) {f = 1; next}} /^```/{f = 0} f' "$TASE_ROOT/README.md" > "$out/example.c"
[ -s "$out/example.c" ] || { echo "no C example found in README.md"; exit 1; }
cc "${warn[@]}" -I"$TASE_ROOT/include" "$out/example.c" "$TASE_ROOT"/src/*.c -o "$out/example"
"$out/example"
echo "README example builds warning-free and runs"

# header_example FILE MARKER: the code lines (" *     ...", indented) of
# the first run of them after the comment line holding MARKER, without the
# comment's prefix.
header_example() {
    awk -v m="$2" 'f && /^ \*     / {n++; sub(/^ \*     /, ""); print; next} f && n {exit} index($0, m) {f = 1}' "$1"
}
# tase/host.h's typed use: its #include lines, then the rest as the body
# of a function with the host `h` and the result `r` it uses.
ex=$(header_example "$TASE_ROOT/include/tase/host.h" "TYPED USE")
[ -n "$ex" ] || { echo "no TYPED USE example found in tase/host.h"; exit 1; }
{
    echo '#include "tase/host.h"'
    grep '^#include' <<<"$ex" || true # none: the example names no header
    echo 'static tase_host_t h;'
    echo 'int example(void);'
    echo 'int example(void)'
    echo '{'
    echo '    int r;'
    grep -v '^#include' <<<"$ex"
    echo '    return r;'
    echo '}'
} >"$out/host_example.c"
cc "${warn[@]}" -I"$TASE_ROOT/include" -c "$out/host_example.c" -o "$out/host_example.o" || {
    cat -n "$out/host_example.c"
    echo "tase/host.h: the TYPED USE example does not compile as written"
    exit 1
}
echo "tase/host.h's TYPED USE example compiles warning-free with only the headers it names"
# tase/bm_dma.h's wiring, after stand-ins for what it takes from the HAL
ex=$(header_example "$TASE_ROOT/port/baremetal/tase/bm_dma.h" "WIRING IT UP")
[ -n "$ex" ] || { echo "no WIRING IT UP example found in tase/bm_dma.h"; exit 1; }
{
    cat <<'PRELUDE'
#include "tase/bm_dma.h"
/* stand-ins for the STM32 HAL */
typedef struct {
    volatile uint32_t CNDTR;
} DMA_HandleTypeDef;
typedef struct {
    DMA_HandleTypeDef *hdmarx;
} UART_HandleTypeDef;
#define __HAL_DMA_GET_COUNTER(hdma) ((hdma)->CNDTR)
extern UART_HandleTypeDef huart3;
int HAL_UART_Receive_DMA(UART_HandleTypeDef *huart, uint8_t *buf, uint16_t size);
void HAL_UART_RxCpltCallback(UART_HandleTypeDef *h);
void uart_rx_start(void);
void uart_rx_poll(uint32_t now_ms);
/* the application's receiver */
static tase_rx_t rx;
static void on_frame(void *user, const tase_frame_t *f)
{
    (void)user;
    (void)f;
}
PRELUDE
    echo "$ex"
} >"$out/bm_dma_example.c"
cc "${warn[@]}" -I"$TASE_ROOT/include" -I"$TASE_ROOT/port/baremetal" -c "$out/bm_dma_example.c" \
    -o "$out/bm_dma_example.o" || {
    cat -n "$out/bm_dma_example.c"
    echo "tase/bm_dma.h: the WIRING IT UP example does not compile as written"
    exit 1
}
echo "tase/bm_dma.h's WIRING IT UP example compiles warning-free"
