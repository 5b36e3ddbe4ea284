#!/bin/sh
# /init of the real-kernel test VM (busybox sh, PID 1). run-in-vm packs it into the initramfs with
# /etc/hsa-kernel.conf (HSA_PLUGIN_DIR), /etc/hsa-kernel.tests (one test binary per line) and
# /modules (the .ko files and their load order).
#
# Algorithm: mount the kernel file systems, insmod the modules in order (there is no modules.dep),
# then for each test binary: create vcan0 and a fresh gpio-sim chip, export where they are, run the
# binary and print its exit code, then remove both so the next binary starts clean. The result
# goes out twice, because either alone can lie: a console line "HSA-KERNEL-RESULT: PASS|FAIL" and
# a byte to qemu's isa-debug-exit port 0xf4 (qemu then exits with 2*byte+1). A panic or an /init
# that dies makes qemu exit 0 with no result line, which the host counts as a failure.

export PATH=/bin:/usr/bin HOME=/root TMPDIR=/tmp GTEST_COLOR=no
. /etc/hsa-kernel.conf

report() {  # $1: 0 pass, 1 fail. Does not return.
  if [ "$1" -eq 0 ]; then echo "HSA-KERNEL-RESULT: PASS"; else echo "HSA-KERNEL-RESULT: FAIL"; fi
  printf "\\00$1" | dd of=/dev/port bs=1 seek=244 count=1 2>/dev/null
  poweroff -f
  sleep 10
}
die() { echo "hsa-kernel-init: setup failed: $*"; report 1; }

mkdir -p /proc /sys /dev /tmp /root
mount -t proc proc /proc || die "mount proc"
mount -t sysfs sysfs /sys || die "mount sysfs"
mount -t devtmpfs devtmpfs /dev || die "mount devtmpfs"
while read -r module; do
  insmod "/modules/$module.ko" || die "insmod $module.ko"
done < /modules/order
mount -t configfs configfs /sys/kernel/config || die "mount configfs"
ip link set lo up || die "ip link set lo up"  # as on any booted system
hostname hsa-kernel-vm || die "hostname"  # as on any booted system: hsad names its system after it
echo "hsa-kernel-init: kernel $(uname -r), modules: $(cut -d' ' -f1 /proc/modules | tr '\n' ' ')"

sim=/sys/kernel/config/gpio-sim/hsa
setup() {
  ip link add dev vcan0 type vcan || die "ip link add dev vcan0 type vcan"
  ip link set vcan0 up || die "ip link set vcan0 up"
  mkdir "$sim" "$sim/bank0" || die "mkdir $sim/bank0 (is gpio-sim loaded?)"
  echo 8 > "$sim/bank0/num_lines" || die "gpio-sim num_lines"
  offset=0
  for name in hsa-estop hsa-valve-enable hsa-pump-enable hsa-limit-low; do
    mkdir "$sim/bank0/line$offset" && echo "$name" > "$sim/bank0/line$offset/name" ||
      die "gpio-sim line$offset name $name"
    offset=$((offset + 1))
  done
  echo 1 > "$sim/live" || die "gpio-sim live"
  chip=$(cat "$sim/bank0/chip_name")
  export HSA_CAN_IFACE=vcan0
  export HSA_GPIO_SIM_CHIP="/dev/$chip"
  export HSA_GPIO_SIM_SYSFS="/sys/devices/platform/$(cat "$sim/dev_name")/$chip"
  export HSA_PLUGIN_DIR
  [ -c "$HSA_GPIO_SIM_CHIP" ] || die "$HSA_GPIO_SIM_CHIP is not a character device"
  [ -f "$HSA_GPIO_SIM_SYSFS/sim_gpio7/pull" ] || die "$HSA_GPIO_SIM_SYSFS/sim_gpio7/pull missing"
}
teardown() {
  ip link del dev vcan0 || die "ip link del dev vcan0"
  echo 0 > "$sim/live" || die "gpio-sim not live"
  rmdir "$sim"/bank0/line* "$sim/bank0" "$sim" || die "rmdir $sim"
}

failed=0
while read -r test; do
  setup
  echo "HSA-KERNEL-TEST-BEGIN $test (HSA_CAN_IFACE=$HSA_CAN_IFACE HSA_GPIO_SIM_CHIP=$HSA_GPIO_SIM_CHIP HSA_GPIO_SIM_SYSFS=$HSA_GPIO_SIM_SYSFS)"
  "$test" < /dev/null
  code=$?
  note=""
  [ "$code" -eq 77 ] && note=" (77: the test found its environment missing, a harness fault)"
  echo "HSA-KERNEL-TEST-END $test exit=$code$note"
  [ "$code" -eq 0 ] || failed=1
  teardown
done < /etc/hsa-kernel.tests
report "$failed"
