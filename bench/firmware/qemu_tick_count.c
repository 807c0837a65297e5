/* A TCG plugin for qemu-system-arm (plugin API version 1, qemu 7.2): the guest instructions of
 * each control tick of a Motwin firmware image, for bench/firmware_figures.py.
 *
 * A tick is delimited by entries of one address, `tick=` (the image's run_control_tick): the
 * count from one entry to the next is all the core executes in that 50 us period (the tick, the
 * main loop, the interrupts, the TMCL link). Each entry of `mark=` (the UART receive interrupt)
 * restarts a window: `skip=` ticks later the next `ticks=` ticks are measured, and their minimum,
 * mean and maximum are appended as one line to `out=`. A window thus holds no received byte.
 * With `profile=`, each window also appends to that file the instructions it executed per
 * translation block start address (one "address instructions executions" line per block, after a
 * "window N" line), which bench/firmware_figures.py maps to functions.
 *
 * Debian ships qemu with plugin support but without qemu-plugin.h (no qemu development
 * package), so the few declarations this file calls are written out below, with the types of
 * plugin API version 1, rather than copying the (GPL) header into the repository. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef uint64_t qemu_plugin_id_t;
typedef struct qemu_info_t qemu_info_t;
struct qemu_plugin_tb;
enum qemu_plugin_cb_flags { QEMU_PLUGIN_CB_NO_REGS, QEMU_PLUGIN_CB_R_REGS, QEMU_PLUGIN_CB_RW_REGS };
enum qemu_plugin_op { QEMU_PLUGIN_INLINE_ADD_U64 };
void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t, void (*)(qemu_plugin_id_t, struct qemu_plugin_tb*));
void qemu_plugin_register_vcpu_tb_exec_cb(struct qemu_plugin_tb*, void (*)(unsigned int, void*),
                                          enum qemu_plugin_cb_flags, void*);
void qemu_plugin_register_vcpu_tb_exec_inline(struct qemu_plugin_tb*, enum qemu_plugin_op, void*, uint64_t);
size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb*);
uint64_t qemu_plugin_tb_vaddr(const struct qemu_plugin_tb*);

__attribute__((visibility("default"))) int qemu_plugin_version = 1;

static uint64_t tick_address, mark_address, skip_ticks = 20, window_ticks = 2000;
static char out_path[1024];
/* One guest CPU: the counters need no locking. */
static uint64_t instructions, at_last_tick, tick_index, window_start = UINT64_MAX;
static uint64_t measured, sum, minimum, maximum;

/* Per block start address: executions so far and at the window's start. Retranslations of one
 * address share a record; the table is fixed, so the inline counters' addresses stay valid. */
enum { kBlockSlots = 1 << 16 };
struct block_record {
  uint64_t address, instructions, executions, at_window_start;
  int used;
};
static struct block_record blocks[kBlockSlots];
static char profile_path[1024];
static uint64_t windows_written;

static struct block_record* block_for(uint64_t address, uint64_t instructions) {
  for (uint64_t probe = 0; probe < kBlockSlots; ++probe) {
    struct block_record* record = &blocks[(address / 2 + probe) % kBlockSlots];
    if (!record->used) {
      record->used = 1;
      record->address = address;
      record->instructions = instructions;
      return record;
    }
    if (record->address == address) return record;
  }
  return NULL; /* full: the block goes unprofiled */
}

static void profile_window_start(void) {
  for (int i = 0; i < kBlockSlots; ++i) blocks[i].at_window_start = blocks[i].executions;
}

static void profile_window_end(void) {
  FILE* out = fopen(profile_path, "a");
  if (!out) return;
  fprintf(out, "window %llu\n", (unsigned long long)windows_written);
  for (int i = 0; i < kBlockSlots; ++i) {
    const struct block_record* record = &blocks[i];
    const uint64_t executions = record->executions - record->at_window_start;
    if (record->used && executions)
      fprintf(out, "%#llx %llu %llu\n", (unsigned long long)record->address,
              (unsigned long long)(executions * record->instructions), (unsigned long long)executions);
  }
  fclose(out);
}

static void on_tick(unsigned int vcpu, void* unused) {
  (void)vcpu;
  (void)unused;
  const uint64_t in_tick = instructions - at_last_tick;
  at_last_tick = instructions;
  ++tick_index;
  /* tick_index - 1 is the tick that just ended; tick_index starts now. */
  if (profile_path[0] && tick_index == window_start && measured == 0) profile_window_start();
  if (window_start == UINT64_MAX || tick_index - 1 < window_start || measured >= window_ticks) return;
  sum += in_tick;
  if (measured == 0 || in_tick < minimum) minimum = in_tick;
  if (in_tick > maximum) maximum = in_tick;
  if (++measured == window_ticks) {
    /* The profile first: the window's line tells the script that both are written. */
    if (profile_path[0]) profile_window_end();
    FILE* out = fopen(out_path, "a");
    if (out) {
      fprintf(out, "window ticks %llu min %llu mean %.1f max %llu\n", (unsigned long long)measured,
              (unsigned long long)minimum, (double)sum / (double)measured, (unsigned long long)maximum);
      fclose(out);
    }
    ++windows_written;
  }
}

static void on_mark(unsigned int vcpu, void* unused) {
  (void)vcpu;
  (void)unused;
  window_start = tick_index + skip_ticks;
  measured = sum = minimum = maximum = 0;
}

static void on_translate(qemu_plugin_id_t id, struct qemu_plugin_tb* tb) {
  (void)id;
  qemu_plugin_register_vcpu_tb_exec_inline(tb, QEMU_PLUGIN_INLINE_ADD_U64, &instructions, qemu_plugin_tb_n_insns(tb));
  const uint64_t address = qemu_plugin_tb_vaddr(tb);
  if (profile_path[0]) {
    struct block_record* record = block_for(address, qemu_plugin_tb_n_insns(tb));
    if (record) qemu_plugin_register_vcpu_tb_exec_inline(tb, QEMU_PLUGIN_INLINE_ADD_U64, &record->executions, 1);
  }
  /* A block that starts at the entry of the function; a branch into its middle starts another block. */
  if (address == tick_address) qemu_plugin_register_vcpu_tb_exec_cb(tb, on_tick, QEMU_PLUGIN_CB_NO_REGS, NULL);
  if (address == mark_address) qemu_plugin_register_vcpu_tb_exec_cb(tb, on_mark, QEMU_PLUGIN_CB_NO_REGS, NULL);
}

__attribute__((visibility("default"))) int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t* info, int argc,
                                                               char** argv) {
  (void)info;
  for (int i = 0; i < argc; ++i) {
    const char* arg = argv[i];
    /* Thumb addresses from the symbol table have bit 0 set; the code starts at the even address. */
    if (!strncmp(arg, "tick=", 5)) tick_address = strtoull(arg + 5, NULL, 0) & ~1ull;
    else if (!strncmp(arg, "mark=", 5)) mark_address = strtoull(arg + 5, NULL, 0) & ~1ull;
    else if (!strncmp(arg, "skip=", 5)) skip_ticks = strtoull(arg + 5, NULL, 0);
    else if (!strncmp(arg, "ticks=", 6)) window_ticks = strtoull(arg + 6, NULL, 0);
    else if (!strncmp(arg, "out=", 4)) snprintf(out_path, sizeof out_path, "%s", arg + 4);
    else if (!strncmp(arg, "profile=", 8)) snprintf(profile_path, sizeof profile_path, "%s", arg + 8);
    else return -1;
  }
  if (!tick_address || !mark_address || !out_path[0] || window_ticks == 0) return -1;
  qemu_plugin_register_vcpu_tb_trans_cb(id, on_translate);
  return 0;
}
