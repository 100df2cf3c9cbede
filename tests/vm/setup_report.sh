#!/bin/sh
cat /tmp/vm_setup.out
