/* boot.S - the multiboot entry of the PC kernel (hal/pcvga).
 *
 * A multiboot (version 1) loader - QEMU's -kernel, GRUB - enters _start in
 * 32-bit protected mode with paging off, interrupts off, EAX = 0x2BADB002 and
 * EBX = the multiboot information. The loader's GDT is not ours to keep, so
 * load a flat one (code 0x08, data 0x10), set up the stack, zero .bss (a
 * loader need not), and call pcvga_start(magic, info) (main.c), which never
 * returns.
 */
    .set MB_MAGIC, 0x1BADB002
    .set MB_FLAGS, 0x00000003          /* modules page-aligned; memory information wanted */

    .section .multiboot, "a"
    .align 4
    .long MB_MAGIC, MB_FLAGS, -(MB_MAGIC + MB_FLAGS)

    .section .text
    .global _start
    .type _start, @function
_start:
    cli
    lgdt gdt_desc
    ljmp $0x08, $1f
1:  movw $0x10, %cx
    movw %cx, %ds
    movw %cx, %es
    movw %cx, %fs
    movw %cx, %gs
    movw %cx, %ss
    movl $__stack_top, %esp
    cld
    movl %eax, %esi                    /* keep magic and info across the fill */
    movl %ebx, %edx
    movl $__bss_start, %edi
    movl $__bss_end, %ecx
    subl %edi, %ecx
    shrl $2, %ecx
    xorl %eax, %eax
    rep stosl
    movl %esi, %eax
    movl %edx, %ebx
    pushl %ebx
    pushl %eax
    call pcvga_start
2:  cli
    hlt
    jmp 2b

    .section .rodata
    .align 8
gdt:
    .quad 0                            /* null */
    .quad 0x00CF9A000000FFFF           /* 0x08: code, base 0, 4 GB, 32-bit */
    .quad 0x00CF92000000FFFF           /* 0x10: data, base 0, 4 GB */
gdt_desc:
    .word gdt_desc - gdt - 1
    .long gdt

    .section .note.GNU-stack, "", @progbits
