/* Ring configuration for the hosted (Linux) build, where the test's
 * "interrupt" is a thread on another CPU core: a full hardware + compiler
 * barrier (GCC/Clang builtin, seq_cst stated so that clang's
 * -Watomic-implicit-seq-cst is quiet). See tase/ring.h, "the hook". */
#ifndef TASE_RING_HOST_CONFIG_H
#define TASE_RING_HOST_CONFIG_H
#define TASE_RING_BARRIER() __atomic_thread_fence(__ATOMIC_SEQ_CST)
#endif
