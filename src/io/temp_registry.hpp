// The temporary files the interrupt handler removes (src/io/interrupt.cpp).
#pragma once

namespace g2s {

// Registers a temporary file name; returns a slot for unregister_temporary (or -1 when full).
int register_temporary(const char* path);
void unregister_temporary(int slot);

}  // namespace g2s
