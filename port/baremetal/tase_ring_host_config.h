/* Ring configuration for the hosted (Linux) build, where the test's
 * "interrupt" is a thread on another CPU core: a full hardware + compiler
 * barrier (GCC/Clang builtin, seq_cst stated so that clang's
 * -Watomic-implicit-seq-cst is quiet). See tase/ring.h, "the hook". */
#ifndef TASE_RING_HOST_CONFIG_H
#define TASE_RING_HOST_CONFIG_H
/* Only when nothing defined it: the library's configuration header
 * (TASE_CONFIG_HEADER, included before this through tase/ring.h) wins. */
#ifndef TASE_RING_BARRIER
#define TASE_RING_BARRIER() __atomic_thread_fence(__ATOMIC_SEQ_CST)
#endif
#endif
