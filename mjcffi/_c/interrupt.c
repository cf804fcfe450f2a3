// Ctrl-C in the long C loops.  Python handles SIGINT by setting a flag that its own
// loop reads, so a C loop running with the GIL released never sees it: the
// KeyboardInterrupt waited for the end of mj_step(m, d, 10**9).  mjcffi puts a handler
// in front of Python's that counts each SIGINT and forwards it; a loop stops at the
// next step boundary once the count moved, and Python raises KeyboardInterrupt when
// the call returns.  Declared in interrupt.h.

#define _GNU_SOURCE

#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <string.h>

#include "interrupt.h"

static atomic_int sigints;                // SIGINTs counted so far
static struct sigaction forwarded;        // the handler ours passes each SIGINT on to
static pthread_t main_thread;
static atomic_int have_main;

static void on_sigint(int signo, siginfo_t* info, void* context) {
  atomic_fetch_add_explicit(&sigints, 1, memory_order_relaxed);
  if (forwarded.sa_flags & SA_SIGINFO) {
    forwarded.sa_sigaction(signo, info, context);
  } else if (forwarded.sa_handler != SIG_DFL && forwarded.sa_handler != SIG_IGN) {
    forwarded.sa_handler(signo);
  }
}

void mjcffi_interrupt_init(unsigned long thread) {
  main_thread = (pthread_t)thread;
  atomic_store(&have_main, 1);
}

// 1 when ours is the installed handler, or was put in front of the installed one.
static int install(void) {
  struct sigaction current;
  if (sigaction(SIGINT, NULL, &current)) {
    return 0;
  }
  if ((current.sa_flags & SA_SIGINFO) && current.sa_sigaction == on_sigint) {
    return 1;
  }
  if (!(current.sa_flags & SA_SIGINFO) &&
      (current.sa_handler == SIG_DFL || current.sa_handler == SIG_IGN)) {
    return 0;                             // nothing to forward to: leave SIGINT alone
  }
  // The one installed now is not ours, so ours cannot be running: `forwarded` is free.
  forwarded = current;
  struct sigaction ours = current;
  ours.sa_sigaction = on_sigint;
  ours.sa_flags = current.sa_flags | SA_SIGINFO;
  return sigaction(SIGINT, &ours, NULL) == 0;
}

int mjcffi_interrupt_token(void) {
  if (!atomic_load(&have_main) || !pthread_equal(pthread_self(), main_thread) || !install()) {
    return -1;
  }
  return atomic_load_explicit(&sigints, memory_order_relaxed);
}

int mjcffi_interrupted(int token) {
  return token >= 0 && atomic_load_explicit(&sigints, memory_order_relaxed) != token;
}
