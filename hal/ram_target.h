/* ram_target.h - the storage half of a target whose VRAM, system-memory buffer
 * and palette are ordinary RAM (the host window and the headless target): it
 * provides the hal_target_* storage functions of hal.h for both. */
#ifndef HAL_RAM_TARGET_H
#define HAL_RAM_TARGET_H

/* Zero both pages, the system-memory buffer and the palette; show page 0. */
void hal_ram_target_reset(void);

#endif
