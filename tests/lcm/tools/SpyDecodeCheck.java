// Decodes LCM-encoded files the way lcm-spy does: finds the Java class by the fingerprint
// in the first 8 bytes (lcm.spy.LCMTypeDatabase scans the class path), constructs it from
// the bytes (which re-checks the fingerprint and reads every field), and prints
// "<file> <class> utime=<header.utime>" per file, or "<file> UNDECODABLE <reason>".
// Run as a single-file program: java -cp lcm.jar:cvslam_lcmtypes.jar SpyDecodeCheck.java F...
import java.io.DataInputStream;
import java.io.ByteArrayInputStream;
import java.nio.file.Files;
import java.nio.file.Paths;

public class SpyDecodeCheck {
  public static void main(String[] args) throws Exception {
    lcm.spy.LCMTypeDatabase types = new lcm.spy.LCMTypeDatabase();
    int failures = 0;
    for (String file : args) {
      byte[] data = Files.readAllBytes(Paths.get(file));
      try {
        long fingerprint = new DataInputStream(new ByteArrayInputStream(data)).readLong();
        Class<?> cls = types.getClassByFingerprint(fingerprint);
        if (cls == null) throw new Exception("no class for fingerprint " + fingerprint);
        Object msg = cls.getConstructor(byte[].class).newInstance((Object) data);
        Object header = cls.getField("header").get(msg);
        long utime = header.getClass().getField("utime").getLong(header);
        System.out.println(file + " " + cls.getName() + " utime=" + utime);
      } catch (Exception e) {
        failures++;
        System.out.println(file + " UNDECODABLE " + e);
      }
    }
    System.exit(failures == 0 ? 0 : 1);
  }
}
