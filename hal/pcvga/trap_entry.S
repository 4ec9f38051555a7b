/* trap_entry.S - the interrupt gates' entry stubs (see trap.h). Each stub makes
 * the stack look the same - an error code (the processor's, or 0) and the
 * vector number above the saved registers - and calls trap_dispatch(frame). */
    .macro stub vec, has_error
    .global trap_stub_\vec
trap_stub_\vec:
    .if \has_error == 0
    pushl $0
    .endif
    pushl $\vec
    jmp trap_common
    .endm

    .section .text
    .irp v, 0,1,2,3,4,5,6,7,9,15,16,18,19,20,22,23,24,25,26,27,28,31,32,39
    stub \v, 0
    .endr
    .irp v, 8,10,11,12,13,14,17,21,29,30
    stub \v, 1
    .endr

trap_common:
    pushal
    pushl %esp                         /* struct trap_frame * */
    call trap_dispatch
    addl $4, %esp
    popal
    addl $8, %esp                      /* vector and error code */
    iretl

    /* the stubs' addresses, by vector, for trap.c's IDT */
    .section .rodata
    .global trap_stubs
    .align 4
trap_stubs:
    .irp v, 0,1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17,18,19,20,21,22,23,24,25,26,27,28,29,30,31
    .long trap_stub_\v
    .endr
    .long trap_stub_32                 /* IRQ 0: the PIT */
    .long trap_stub_39                 /* IRQ 7: the master PIC's spurious interrupt */

    .section .note.GNU-stack, "", @progbits
