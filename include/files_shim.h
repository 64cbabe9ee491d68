/* File-system calls of the output stage (see src/io/files_shim.c), for module files. */
#ifndef RC_FILES_SHIM_H
#define RC_FILES_SHIM_H
/* Write "<host>.<pid>" into buf (n bytes, NUL-terminated), the host name reduced to the
   characters [A-Za-z0-9_-] (others become '_'); returns its length. */
int rc_run_token(char *buf, int n);
/* Open the folder dir and take an exclusive flock on it (waits for other holders; retried
   when a signal interrupts the wait). Returns the descriptor, or -1 when the folder cannot
   be opened or locked (then the caller goes on without the lock). */
int rc_lock_dir(const char *dir);
/* Release a lock from rc_lock_dir (closes the descriptor); nothing for fd < 0. */
void rc_unlock_dir(int fd);
/* What is at path (not following a final symbolic link): 0 nothing, 1 a regular file or a
   symbolic link, 2 a folder, 3 something else (device, fifo, socket), -1 cannot tell. */
int rc_path_kind(const char *path);
/* What path names, following symbolic links: 0 nothing, 1 a regular file, 2 a folder,
   3 something else (fifo, device, socket), -1 cannot tell. */
int rc_file_kind(const char *path);
/* The longest name of one entry of the folder dir (pathconf _PC_NAME_MAX), -1 when the
   system does not say. */
long rc_name_max(const char *dir);
/* 1 when the folder dir can take new entries (write and search permission), else 0. */
int rc_dir_writable(const char *dir);
/* A file's data written at given offsets (the raw data of reserved HDF5 datasets): open
   for writing (-1 on failure), write n bytes at offset (0 or an errno; short writes and
   EINTR retried), close (0 or an errno). */
int rc_open_data(const char *path);
int rc_write_at(int fd, const void *buf, long long n, long long offset);
int rc_close_data(int fd);
/* The text of errno value e into buf (n bytes, NUL-terminated); returns its length. */
int rc_error_text(int e, char *buf, int n);
#endif
